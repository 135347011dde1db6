"""Every flag of `haarshift relight precompute` is a keyword of `haarshift.relight.precompute`
of the same name (snake_case), and gives the same cache, byte for byte; a request either
refuses is refused by both with the library's one message. The flags are read from the
command's own --help, so a flag added there without a keyword here fails this test."""
import inspect
import json
import re

import numpy as np
import pytest

import haarshift

# Each flag: the command line's arguments and Python's keywords that exercise it (with what it
# needs beside it), on a ball of 54 vertices at cube or lat-long 4. The ground plane of 2 x 2
# cells gives a refinement and a bounce something to do.
GROUND = (["--ground-plane", "--ground-cells", "2"], dict(ground_plane=True, ground_cells=2))
CASES = {
    "param": (["--param", "cube"], dict(param="cube")),
    "resolution": (["--resolution", "8"], dict(resolution=8)),
    "keep-visibility": (["--keep-visibility", "5"], dict(keep_visibility=5)),
    "visibility-samples": (["--visibility-samples", "2"], dict(visibility_samples=2)),
    "seed": (["--visibility-samples", "2", "--seed", "7"], dict(visibility_samples=2, seed=7)),
    "order": (["--order", "direction", "--map-size", "64"], dict(order="direction", map_size=64)),
    "map-size": (["--order", "direction", "--map-size", "32"], dict(order="direction", map_size=32)),
    "ray-tracer": (["--ray-tracer", "packets"], dict(ray_tracer="packets")),
    "sh-bands": (["--sh-bands", "2"], dict(sh_bands=2)),
    "bounces": (["--bounces", "1", *GROUND[0]], dict(bounces=1, **GROUND[1])),
    "bounce-from": (
        ["--shard", "0/2", "--bounces", "1", "--bounce-from", "{b0}", *GROUND[0]],
        dict(shard="0/2", bounces=1, bounce_from="{b0}", **GROUND[1]),
    ),
    "refine": (["--refine", "0.3", *GROUND[0]], dict(refine=0.3, **GROUND[1])),
    "max-vertices": (
        ["--refine", "0.05", "--max-vertices", "70", *GROUND[0]],
        dict(refine=0.05, max_vertices=70, **GROUND[1]),
    ),
    "refine-light": (
        ["--refine", "0.3", "--refine-light", "{sky}", *GROUND[0]],
        dict(refine=0.3, refine_light="{sky}", **GROUND[1]),
    ),
    "shard": (["--shard", "1/2"], dict(shard="1/2")),
    # auto, from a Kubernetes Indexed Job's completion index (set for both below).
    "shards": (["--shard", "auto", "--shards", "2"], dict(shard="auto", shards=2)),
    "force": (["--force"], dict(force=True)),  # over an existing file (written below)
    "ground-plane": (["--ground-plane"], dict(ground_plane=True)),
    "ground-cells": GROUND,
    # Not recorded in the cache: the same bytes under a limit the run fits in.
    "memory-limit": (["--memory-limit", "64MiB"], dict(memory_limit="64MiB")),
}
# Flags that are not options of the computation.
NOT_OPTIONS = {
    "help": "clap's own help, not an option of the computation",
    "version": "the program's version, not an option of the computation",
    "output": "the file every case above writes and compares (Python's output=)",
}
# Refused by both, with the library's message (Python's exception text is on the command
# line's one error line).
REFUSALS = [
    ["--refine", "3"],
    ["--resolution", "6"],
    ["--bounces", "9"],
    ["--order", "direction", "--bounces", "1"],
    ["--shard", "0/2", "--order", "direction"],
    ["--shard", "0/2", "--bounces", "1"],
    ["--refine", "0.2", "--visibility-samples", "2"],
    ["--refine", "0.2", "--shard", "0/2"],
    ["--memory-limit", "1KiB"],
    ["--memory-limit", "0"],
    ["--ground-plane", "--ground-cells", "0"],
    ["--shard", "2/2"],
]


def flags(help_text):
    """The long flags the command's --help lists."""
    return sorted(set(re.findall(r"^\s+(?:-\w, )?--([a-z][a-z-]*)", help_text, re.MULTILINE)))


def keywords(args):
    """Command-line arguments as Python keywords: `--flag V` is `flag=V` (numbers as
    numbers), a flag alone is `flag=True`."""
    out, k = {}, 0
    while k < len(args):
        name = args[k][2:].replace("-", "_")
        if k + 1 < len(args) and not args[k + 1].startswith("--"):
            value = args[k + 1]
            for kind in (int, float):
                try:
                    value = kind(value)
                    break
                except ValueError:
                    pass
            out[name], k = value, k + 2
        else:
            out[name], k = True, k + 1
    return out


@pytest.fixture
def ball(tmp_path):
    """A ball of 54 vertices (scene file), a sky brighter overhead (.npy), and `b0.hsr`: the
    ball on its ground precomputed without bounces, what a merge of bounce 0 gives."""
    path = tmp_path / "ball.json"
    path.write_text(json.dumps({"objects": [{"generator": {"sphere": {"cells": 2}}}]}))
    sky = np.ones((8, 16, 3))
    sky[:2] = [40.0, 30.0, 20.0]
    np.save(tmp_path / "sky.npy", sky)
    haarshift.relight.precompute(path, resolution=4, output=tmp_path / "b0.hsr", **GROUND[1])
    return path, {"b0": str(tmp_path / "b0.hsr"), "sky": str(tmp_path / "sky.npy")}


def test_every_flag_is_a_keyword_of_the_same_name(cli):
    listed = flags(cli("relight", "precompute", "--help").stdout)
    assert "visibility-samples" in listed and "output" in listed
    assert sorted(set(listed) - set(NOT_OPTIONS)) == sorted(CASES), "a flag without a case here"
    parameters = inspect.signature(haarshift.relight.precompute).parameters
    for flag in listed:
        if flag not in ("help", "version"):
            assert flag.replace("-", "_") in parameters, f"--{flag} has no keyword"
    # Python's keywords are the command line's, and no others.
    options = [f.replace("-", "_") for f in listed if f not in ("help", "version")]
    assert sorted(parameters) == sorted(["scene"] + options)


@pytest.mark.parametrize("flag", sorted(CASES))
def test_each_flag_gives_the_command_line_s_cache(cli, ball, tmp_path, monkeypatch, flag):
    scene, files = ball
    args, options = CASES[flag]
    args = [a.format(**files) for a in args]
    options = {k: v.format(**files) if isinstance(v, str) else v for k, v in options.items()}
    assert keywords(args) == options  # the case names one thing both ways
    monkeypatch.setenv("JOB_COMPLETION_INDEX", "1")
    ours, theirs = tmp_path / "python.hsr", tmp_path / "cli.hsr"
    if flag == "force":
        ours.write_bytes(b"replaced")
        theirs.write_bytes(b"replaced")
    base = ["--resolution", "4"] if flag != "resolution" else []
    cli("relight", "precompute", scene, *base, *args, "-o", theirs)
    resolution = {} if flag == "resolution" else dict(resolution=4)
    haarshift.relight.precompute(scene, output=ours, **resolution, **options)
    assert theirs.read_bytes() == ours.read_bytes()
    assert len(ours.read_bytes()) > 1000


@pytest.mark.parametrize("args", REFUSALS, ids=" ".join)
def test_a_refusal_is_the_same_message_both_ways(cli, ball, tmp_path, args):
    scene, _ = ball
    out = tmp_path / "out.hsr"
    base = [] if "--resolution" in args else ["--resolution", "4"]
    result = cli("relight", "precompute", scene, *base, *args, "-o", out, check=False)
    assert result.returncode != 0
    with pytest.raises((ValueError, OSError, MemoryError)) as refused:
        haarshift.relight.precompute(scene, output=out, **keywords(base + args))
    assert str(refused.value) in result.stderr, result.stderr
    assert not out.exists()
