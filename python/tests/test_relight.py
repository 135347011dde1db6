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



@pytest.fixture
def cached(tmp_path):
    """Two balls on a ground plane precomputed at lat-long 8 with 3 bands of harmonics, its
    cache written, and a sky (a file) brighter overhead."""
    sky = np.ones((16, 32, 3))
    sky[:5] = [4.0, 3.0, 2.0]
    np.save(tmp_path / "sky.npy", sky)
    ball = {"generator": {"sphere": {"cells": 3}}}
    spec = {
        "objects": [dict(ball, name="a"), dict(ball, name="b", transform={"translate": [2.5, 0, 0]})],
        "ground_plane": True,
    }
    path = tmp_path / "balls.json"
    path.write_text(json.dumps(spec))
    out = tmp_path / "balls.hsr"
    cache = haarshift.relight.precompute(path, resolution=8, sh_bands=3, output=out)
    return cache, out, tmp_path / "sky.npy"


RENDERS = [
    (dict(), []),
    (dict(keep_light=30, keep_visibility=20), ["--keep-light", "30", "--keep-visibility", "20"]),
    (dict(brdf="phong:20"), ["--brdf", "phong:20"]),
    (dict(brdf="phong:20", rotation_cache=8), ["--brdf", "phong:20", "--rotation-cache", "8"]),
    (dict(brdf="blinn:20"), ["--brdf", "blinn:20"]),
    (dict(basis="sh"), ["--basis", "sh"]),
    (dict(basis="sh", brdf="phong:10"), ["--basis", "sh", "--brdf", "phong:10"]),
    (dict(basis="ambient"), ["--basis", "ambient"]),
]


@pytest.mark.parametrize("options,flags", RENDERS)
def test_a_shader_agrees_with_relight_render(cli, cached, tmp_path, options, flags):
    cache, path, sky = cached
    shader = haarshift.relight.Shader(haarshift.relight.Cache.read(path), **options)
    ours, report = shader.shade(sky, yaw=40.0)
    assert ours.shape == (cache.vertex_count, 3)
    assert set(report) == {"encode_seconds", "rotate_seconds", "shade_seconds", "description"}
    out = tmp_path / "v.npy"
    cli("relight", "render", path, "--env", sky, "--yaw", "40", *flags, "--vertices", out,
        "--width", "32", "--height", "24", "-o", tmp_path / "frame.png")
    want = np.load(out)
    assert np.array_equal(ours.astype(np.float32), want)
    # The same frame again (a glossy shader's cache now warm) gives the same radiance.
    again, _ = shader.shade(sky, yaw=40.0)
    assert np.array_equal(again, ours)


def test_a_bounce_cache_is_the_command_line_s_and_shades_as_relight_render(cli, cached, tmp_path):
    _, path, sky = cached
    scene = tmp_path / "balls.json"
    ours = tmp_path / "ours.hsr"
    cache = haarshift.relight.precompute(scene, resolution=8, bounces=2, output=ours)
    assert cache.bounces == 2
    theirs = tmp_path / "theirs.hsr"
    cli("relight", "precompute", scene, "--resolution", "8", "--bounces", "2", "-o", theirs)
    assert ours.read_bytes() == theirs.read_bytes()
    radiance, _ = haarshift.relight.Shader(haarshift.relight.Cache.read(ours)).shade(sky)
    out = tmp_path / "v.npy"
    cli("relight", "render", ours, "--env", sky, "--vertices", out,
        "--width", "32", "--height", "24", "-o", tmp_path / "frame.png")
    assert np.array_equal(radiance.astype(np.float32), np.load(out))
    # The bounces add light: more than the direct cache's everywhere, somewhere strictly.
    direct, _ = haarshift.relight.Shader(haarshift.relight.Cache.read(path)).shade(sky)
    assert (radiance >= direct - 1e-6).all() and (radiance > direct + 1e-4).any()


def test_the_cache_object(cached):
    cache, path, _ = cached
    read = haarshift.relight.Cache.read(path)
    assert read.vertex_count == cache.vertex_count == read.positions.shape[0]
    assert read.object_vertices < read.vertex_count  # the ground plane's come last
    assert read.param == ("latlong", 8) and read.sh_bands == 3
    assert read.triangles.max() < read.vertex_count
    assert np.allclose(np.linalg.norm(read.normals, axis=1), 1.0)
    assert np.array_equal(read.albedo, cache.albedo)


def test_a_shader_turns_the_lighting_and_follows_the_eye(cached):
    cache, _, sky = cached
    lambert = haarshift.relight.Shader(cache)
    a, _ = lambert.shade(sky)
    # The sky depends on elevation only: a yaw changes nothing, a pitch does.
    assert np.array_equal(a, lambert.shade(sky, yaw=90.0)[0])
    b, _ = lambert.shade(sky, pitch=90.0)
    assert not np.array_equal(a, b)
    c, _ = lambert.shade(np.load(sky), eye=(0.0, 9.0, 0.0))
    assert np.array_equal(a, c)  # Lambertian: the eye changes nothing
    phong = haarshift.relight.Shader(cache, brdf="phong:20")
    d, _ = phong.shade(sky, eye=(0.0, 9.0, 0.0))
    e, _ = phong.shade(sky, eye=(9.0, 1.0, 0.0))
    assert not np.array_equal(d, e)


def test_bad_shader_input(cached, tmp_path):
    cache, path, sky = cached
    with pytest.raises(FileNotFoundError, match="missing.hsr"):
        haarshift.relight.Cache.read(tmp_path / "missing.hsr")
    (tmp_path / "junk.hsr").write_bytes(b"not a cache")
    with pytest.raises(OSError, match="junk.hsr"):
        haarshift.relight.Cache.read(tmp_path / "junk.hsr")
    with pytest.raises(ValueError, match='unknown value "pixel"'):
        haarshift.relight.Shader(cache, basis="pixel")
    with pytest.raises(ValueError, match="uses every band stored"):
        haarshift.relight.Shader(cache, basis="sh", keep_light=10)
    with pytest.raises(ValueError, match="sh shades zonal lobes only"):
        haarshift.relight.Shader(cache, basis="sh", brdf="blinn:20")
    with pytest.raises(ValueError, match="the BRDF is lambert"):
        haarshift.relight.Shader(cache, rotation_cache=8)
    with pytest.raises(ValueError, match="albedo"):
        haarshift.relight.Shader(cache, albedo=(2.0, 0.0, 0.0))
    bare_path = tmp_path / "bare.hsr"
    haarshift.relight.precompute(tmp_path / "balls.json", resolution=8, output=bare_path)
    with pytest.raises(OSError, match="bare.hsr: the cache holds no spherical-harmonic"):
        haarshift.relight.Shader(haarshift.relight.Cache.read(bare_path), basis="sh")
    shader = haarshift.relight.Shader(cache)
    with pytest.raises(ValueError, match="give env="):
        shader.shade()
    with pytest.raises(ValueError, match="eye"):
        shader.shade(sky, eye=(float("nan"), 0.0, 0.0))
    with pytest.raises(ValueError, match="lat-long"):
        shader.shade(np.ones((8, 8)))
    with pytest.raises(FileExistsError):
        haarshift.relight.precompute(tmp_path / "balls.json", resolution=8, output=bare_path)
