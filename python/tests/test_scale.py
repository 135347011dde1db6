"""The sharded precomputation fanned out over a real Dask cluster (two worker processes) and
merged: the cache an unsharded run writes, byte for byte."""
import json
import os

import numpy as np
import pytest
from dask.distributed import Client, LocalCluster

import haarshift
from conftest import needs

OPTIONS = dict(param="cube", resolution=4, visibility_samples=2, seed=3, sh_bands=2)


@pytest.fixture
def balls(tmp_path):
    """Two balls on a ground plane: 192 + 1089 vertices, the ground shadowed by the balls."""
    ball = {"generator": {"sphere": {"cells": 3}}}
    spec = {
        "objects": [ball, dict(ball, transform={"translate": [2.5, 0, 0]})],
        "ground_plane": True,
    }
    path = tmp_path / "balls.json"
    path.write_text(json.dumps(spec))
    return path


def test_shards_on_a_dask_local_cluster_merge_into_the_unsharded_cache(tmp_path, balls):
    count = 5

    def shard(i):
        # Runs in a worker process: the path it wrote and who wrote it.
        path = haarshift.relight.precompute(
            balls, shard=(i, count), output=tmp_path / f"part-{i}.hsr", **OPTIONS
        )
        return path, os.getpid()

    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster, Client(cluster) as client:
        done = client.gather(client.map(shard, range(count)))
        workers = set(client.run(os.getpid).values())
    assert len(workers) == 2 and os.getpid() not in workers
    assert {pid for _, pid in done} <= workers
    parts = [path for path, _ in done]
    assert parts == [str(tmp_path / f"part-{i}.hsr") for i in range(count)]

    merged = haarshift.relight.merge(list(reversed(parts)), output=tmp_path / "merged.hsr")
    whole = haarshift.relight.precompute(balls, output=tmp_path / "whole.hsr", **OPTIONS)
    assert merged.vertex_count == whole.vertex_count == 1281
    assert (tmp_path / "merged.hsr").read_bytes() == (tmp_path / "whole.hsr").read_bytes()


def test_a_shard_is_skipped_when_complete_and_bad_shards_are_refused(tmp_path, balls):
    part = tmp_path / "part-1.hsr"
    assert haarshift.relight.precompute(balls, shard=(1, 2), output=part, **OPTIONS) == str(part)
    before = part.stat().st_mtime_ns
    haarshift.relight.precompute(balls, shard=(1, 2), output=part, **OPTIONS)
    assert part.stat().st_mtime_ns == before  # complete: not written again
    with pytest.raises(OSError, match="holds shard 1/2, not 0/2"):
        haarshift.relight.precompute(balls, shard=(0, 2), output=part, **OPTIONS)
    with pytest.raises(ValueError, match="a shard is written to a file: give --output"):
        haarshift.relight.precompute(balls, shard=(0, 2), **OPTIONS)
    with pytest.raises(ValueError, match="below the count"):
        haarshift.relight.precompute(balls, shard=(2, 2), output=part, **OPTIONS)
    with pytest.raises(OSError, match="part-1.hsr: the shards do not cover"):
        haarshift.relight.merge([part])
    taken = tmp_path / "taken.hsr"
    taken.write_bytes(b"mine")
    with pytest.raises(FileExistsError):
        haarshift.relight.merge([part], output=taken)
    assert taken.read_bytes() == b"mine"


def test_either_ray_tracer_writes_the_balls_cache_and_an_unknown_one_is_refused(tmp_path, balls):
    # Embree is the default where it loads; our packets answer the balls' rays alike, and each
    # cache names the tracer that cast it.
    packets = tmp_path / "packets.hsr"
    haarshift.relight.precompute(balls, output=packets, ray_tracer="packets", **OPTIONS)
    assert haarshift.relight.Cache.read(packets).ray_tracer == "packets"
    with pytest.raises(ValueError, match="unknown value \"optix\""):
        haarshift.relight.precompute(balls, ray_tracer="optix", **OPTIONS)
    embree = tmp_path / "embree.hsr"
    try:
        haarshift.relight.precompute(balls, output=embree, ray_tracer="embree", **OPTIONS)
    except ValueError as e:
        assert "libembree3-3" in str(e), e
        needs("embree", f"no Embree: {e}")
    a, b = (haarshift.relight.Cache.read(f) for f in (embree, packets))
    assert a.ray_tracer == "embree"
    for field in ("positions", "normals", "triangles", "albedo"):
        assert np.array_equal(getattr(a, field), getattr(b, field)), field
    sky = np.random.default_rng(5).random((16, 32, 3)).astype(np.float32)
    shade = lambda c: haarshift.relight.Shader(c).shade(sky)[0]  # noqa: E731
    assert np.array_equal(shade(a), shade(b))
