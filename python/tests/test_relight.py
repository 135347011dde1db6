import json

import numpy as np
import pytest

import haarshift

# Small fields, so that a scene builds in a fraction of a second.
FIELDS = dict(resolution=8, circles=4, circle_points=8, shells=3, shell_grid=3)
FLAGS = ["--resolution", "8", "--circles", "4", "--circle-points", "8", "--shells", "3", "--shell-grid", "3"]


@pytest.fixture
def scene(tmp_path):
    """Two balls on a ground plane under a sky brighter overhead, named by the scene file."""
    sky = np.ones((16, 32, 3))
    sky[:6] = [4.0, 3.0, 2.0]
    np.save(tmp_path / "sky.npy", sky)
    ball = {"generator": {"sphere": {"cells": 4}}}
    spec = {
        "objects": [dict(ball, name="a"), dict(ball, name="b", transform={"translate": [2.5, 0, 0]})],
        "ground_plane": True,
        "environment": {"path": "sky.npy", "yaw": 30.0},
    }
    path = tmp_path / "balls.json"
    path.write_text(json.dumps(spec))
    return path, sky


def test_agrees_with_the_command_line(cli, scene, tmp_path):
    path, _ = scene
    ours = haarshift.relight.scene(path, keep_light=40, keep_field=20, **FIELDS)
    assert ours.dtype == np.float32 and ours.shape[1] == 3
    out = tmp_path / "v.npy"
    cli("relight", "scene", path, *FLAGS, "--keep-light", "40", "--keep-field", "20",
        "--vertices", out, "-o", tmp_path / "frame.png")
    assert np.array_equal(ours, np.load(out))


def test_haar_approaches_the_ray_cast_truth(scene):
    """Error / RMS against ray casting falls as the fields grow denser (measured: 0.104 with
    4 x 8 circle points and 3 shells of 27, 0.013 with 20 x 40 and 6 of 75, 0.0066 at seed
    001's 100 x 200 and 20 of 243), and grows when the factors are pruned."""
    path, _ = scene
    truth = haarshift.relight.scene(path, method="reference", resolution=8)
    assert truth.dtype == np.float64
    error = lambda v: np.sqrt(((v - truth) ** 2).mean() / (truth ** 2).mean())
    sparse = error(haarshift.relight.scene(path, **FIELDS))
    denser = error(haarshift.relight.scene(path, resolution=8, circles=20, circle_points=40, shells=6, shell_grid=5))
    seed = error(haarshift.relight.scene(path, resolution=8))
    assert seed < denser < sparse < 0.15
    assert seed < 0.01
    pruned = error(haarshift.relight.scene(path, resolution=8, keep_light=10, keep_visibility=5, keep_field=5))
    assert pruned > seed


def test_the_environment_as_a_file_or_an_array(scene):
    path, sky = scene
    from_file = haarshift.relight.scene(path, **FIELDS)
    from_array = haarshift.relight.scene(path, env=sky, **FIELDS)
    assert np.array_equal(from_file, from_array)
    turned = haarshift.relight.scene(path, env=sky, yaw=120.0, **FIELDS)
    assert not np.array_equal(turned, from_file)


def test_bad_input(scene, tmp_path):
    path, _ = scene
    with pytest.raises(FileNotFoundError, match="missing.json"):
        haarshift.relight.scene(tmp_path / "missing.json", **FIELDS)
    with pytest.raises(ValueError, match='method: unknown value "pixel"'):
        haarshift.relight.scene(path, method="pixel", **FIELDS)
    bare = tmp_path / "bare.json"
    bare.write_text(json.dumps({"objects": [{"name": "a", "generator": {"sphere": {"cells": 2}}}]}))
    with pytest.raises(ValueError, match="give env="):
        haarshift.relight.scene(bare, **FIELDS)
    broken = tmp_path / "broken.json"
    broken.write_text('{"objects": [{"name": "a", "mesh": "nowhere.ply"}]}')
    with pytest.raises(OSError, match="nowhere.ply"):
        haarshift.relight.scene(broken, **FIELDS)
    with pytest.raises(ValueError, match="lat-long"):
        haarshift.relight.scene(path, env=np.ones((8, 8)), **FIELDS)
