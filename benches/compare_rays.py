#!/usr/bin/env python3
"""Occlusion rays per second: haarshift's vertex-major precomputation against Intel Embree.

The rays are haarshift's own: `tools/measure/src/bin/rays.rs --export` records every ray the
precomputation casts (cube 32 x 32 texel centres above each vertex's horizon, one ray each,
origins 1e-4 of the diagonal off the surface along the normal: the CLI's `relight precompute
SCENE --param cube --resolution 32 --visibility-samples 1`) as f32 .npy arrays with its
answers. Embree casts the same f32 rays through `embreex` (Embree 4.4.0, its only occlusion
query: `rtcOccluded1` per ray, looped in C; the binding offers no packet or stream query), on
one thread, and on two as two processes each casting half the rays at once (the slower
process's time). haarshift's figures are the whole precomputation (rays and the Haar encoding
of every vertex's transport, `vertex_range`) with RAYON_NUM_THREADS=1 and 2, the fastest of
three, with each of its ray tracers (`RayTracer`): Embree 3.13.5 (Debian's libembree3, its
16-wide packet query `rtcOccluded16`, the default where it is installed) and our own packets.
BVH builds are timed apart, not in the rates. Every ray answered differently by haarshift's
tracers and Embree 4.4, or by the two tracers, is worked out in f64 against every triangle
to say which answer is exact.

Scenes: the bunny (every vertex), the cubes scene (testdata/scenes/cubes.json, 85,860
vertices: a run of 2,000 of them) and a generated scene of 600,000 triangles (14 x 14 cubes of
16 x 16 cells a face: 2,000 vertices). Writes benches/rays_results.md.

    apt-get install libembree3-3          # haarshift's Embree tracer, loaded at run time (.ci/run installs it)
    pip install --user numpy embreex      # test-only; not part of .ci/run
    python3 benches/compare_rays.py
"""

import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "target" / "release" / "examples" / "rays"
BIG_SCENE = {
    "objects": [{"generator": {"cubes": {"count": 14, "cells": 16, "distance": 1.5}}}],
}


def scenes(work):
    big = work / "big.json"
    big.write_text(json.dumps(BIG_SCENE))
    return [
        ("bunny", ROOT / "testdata" / "meshes" / "bunny.ply", None),
        ("cubes", ROOT / "testdata" / "scenes" / "cubes.json", "40000..42000"),
        ("600k triangles", big, "100000..102000"),
    ]


def embree_child(directory, first, end):
    """Builds the scene, waits for a line on stdin, casts rays first..end, prints seconds."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs

    d = pathlib.Path(directory)
    scene = rs.EmbreeScene()
    mc.TriangleMesh(scene, np.load(d / "vertices.npy"), np.load(d / "triangles.npy"))
    origins = np.ascontiguousarray(np.load(d / "origins.npy")[first:end])
    directions = np.ascontiguousarray(np.load(d / "directions.npy")[first:end])
    scene.run(origins[:16], directions[:16], query="OCCLUDED")  # commits the scene
    sys.stdin.readline()
    start = time.perf_counter()
    hit = scene.run(origins, directions, query="OCCLUDED")
    seconds = time.perf_counter() - start
    np.save(d / f"embree-{first}.npy", (hit != -1).astype(np.uint8))
    print(seconds, flush=True)


def embree(directory, n, processes):
    """Seconds for `processes` processes each casting its share of the n rays at once."""
    bounds = [n * k // processes for k in range(processes + 1)]
    children = [
        subprocess.Popen(
            [sys.executable, __file__, "--embree-child", str(directory), str(a), str(b)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )
        for a, b in zip(bounds, bounds[1:])
    ]
    time.sleep(0.5)
    for c in children:
        c.stdin.write("go\n")
        c.stdin.flush()
    seconds = max(float(c.communicate()[0]) for c in children)
    blocked = np.concatenate([np.load(directory / f"embree-{a}.npy") for a in bounds[:-1]])
    return seconds, blocked


def haarshift(path, vertices, threads, *extra):
    args = [str(EXAMPLE), str(path), "--repeat", "3", *extra]
    if vertices:
        args += ["--vertices", vertices]
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run(args, env=env, check=True, capture_output=True, text=True).stdout
    return json.loads(out)


def grazing(directory, different):
    """For rays on which the two disagree: the cosine between the ray and the plane of the
    triangle Embree's closest-hit query finds along it (none: no triangle found)."""
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs

    v, t = np.load(directory / "vertices.npy"), np.load(directory / "triangles.npy")
    scene = rs.EmbreeScene()
    mc.TriangleMesh(scene, v, t)
    o = np.ascontiguousarray(np.load(directory / "origins.npy")[different])
    d = np.ascontiguousarray(np.load(directory / "directions.npy")[different])
    hits = scene.run(o, d, query="INTERSECT", output=True)
    cosines = []
    for k, prim in enumerate(hits["primID"]):
        if prim < 0:
            cosines.append(None)
            continue
        a, b, c = v[t[prim]].astype(np.float64)
        n = np.cross(b - a, c - a)
        cosines.append(abs(n @ d[k]) / np.linalg.norm(n) / np.linalg.norm(d[k]))
    return cosines


def exact(directory, rays):
    """Each ray's answer worked out in f64 against every triangle (Moller-Trumbore on the
    f32 inputs, whose products f64 carries almost exactly): whether it is blocked, and its
    margin, the least barycentric coordinate of the triangle it meets deepest (negative when
    it meets none: how far it passes outside the nearest edge). A margin near 0 is a ray
    through an edge, whose f32 answer is decided by rounding."""
    v = np.load(directory / "vertices.npy").astype(np.float64)
    t = np.load(directory / "triangles.npy")
    a = v[t[:, 0]]
    e1, e2 = v[t[:, 1]] - a, v[t[:, 2]] - a
    origins = np.load(directory / "origins.npy", mmap_mode="r")
    directions = np.load(directory / "directions.npy", mmap_mode="r")
    answers = []
    for i in rays:
        o, d = origins[i].astype(np.float64), directions[i].astype(np.float64)
        p = np.cross(d, e2)
        det = np.einsum("ij,ij->i", e1, p)
        with np.errstate(divide="ignore", invalid="ignore"):
            s = o - a
            u = np.einsum("ij,ij->i", s, p) / det
            q = np.cross(s, e1)
            w = (q @ d) / det
            along = np.einsum("ij,ij->i", e2, q) / det
        least = np.minimum(np.minimum(u, w), 1.0 - u - w)
        ahead = (det != 0) & (along >= 0) & np.isfinite(least)
        margin = float(least[ahead].max()) if ahead.any() else float("-inf")
        answers.append((margin >= 0, margin))
    return answers


def whose(name):
    """The possessive of a name: "our packets'", "Embree 4.4's"."""
    return name + ("'" if name.endswith("s") else "'s")


def arbitrate(directory, name, who, against, ours, different):
    """One line: who of `who` (answers `ours`) and `against` the f64 answer agrees with on the
    rays they answer differently, and how near an edge those rays pass."""
    answers = exact(directory, different)
    truth = np.array([b for b, _ in answers])
    margins = np.abs([m for _, m in answers])
    agree = int((truth == ours[different].astype(bool)).sum())
    return (
        f"- {name}: {len(different)} rays answered differently by {who} and {against}. "
        f"In f64 against every triangle, the exact answer is {whose(who)} on {agree} and "
        f"{whose(against)} on {len(different) - agree}; every one passes within "
        f"{margins.max():.1e} (barycentric) of a triangle's edge (median {np.median(margins):.1e})"
    )


def main():
    if len(sys.argv) == 5 and sys.argv[1] == "--embree-child":
        embree_child(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
        return
    subprocess.run(
        ["cargo", "build", "--release", "-p", "haarshift-measure", "--bin", "rays"],
        cwd=ROOT,
        check=True,
    )
    import embreex

    load = os.getloadavg()
    rows, notes = [], []
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for name, path, vertices in scenes(work):
            directory = work / name.replace(" ", "-")
            export = ["--export", str(directory)]
            args = [str(EXAMPLE), str(path), *export] + (["--vertices", vertices] if vertices else [])
            subprocess.run(args, check=True)
            ours = np.load(directory / "blocked.npy")
            packets = np.load(directory / "packets.npy")
            n = len(ours)
            e1, blocked = embree(directory, n, 1)
            e1 = min(e1, embree(directory, n, 1)[0])
            e2 = min(embree(directory, n, 2)[0] for _ in range(2))
            h1, h2 = (haarshift(path, vertices, t, "--tracer", "embree") for t in (1, 2))
            p1, p2 = (haarshift(path, vertices, t, "--tracer", "packets") for t in (1, 2))
            assert h1["rays"] == n == h2["rays"] == len(blocked) == p1["rays"], (h1, p1, n)
            for who, answers in (("haarshift (Embree 3)", ours), ("our packets", packets)):
                different = np.flatnonzero(blocked != answers)
                if len(different):
                    notes.append(arbitrate(directory, name, who, "Embree 4.4", answers, different))
            first = np.flatnonzero(blocked != ours)[:10]
            if len(first):
                listed = ", ".join(
                    f"ray {i}: haarshift {'blocked' if ours[i] else 'open'}, Embree 4.4 "
                    f"{'blocked' if blocked[i] else 'open'}, "
                    + ("no triangle" if c is None else f"cos to the triangle's plane {c:.2e}")
                    for i, c in zip(first, grazing(directory, first))
                )
                notes.append(f"  The first ten: {listed}")
            changed = np.flatnonzero(packets != ours)
            if len(changed):
                notes.append(
                    arbitrate(directory, name, "haarshift (Embree 3)", "our packets", ours, changed)
                )
            rate = lambda s: n / s / 1e6
            rows.append(
                f"| {name} | {h1['triangles']:,} | {h1['vertices']:,} | {n:,} | "
                f"{int(ours.sum()):,} / {int(packets.sum()):,} / {int(blocked.sum()):,} | "
                f"{h1['build_seconds']:.2f} / {p1['build_seconds']:.2f} | "
                f"{rate(e1):.2f} | {rate(h1['seconds']):.2f} | **{e1 / h1['seconds']:.2f}x** | "
                f"{rate(p1['seconds']):.2f} | {e1 / p1['seconds']:.2f}x | "
                f"{rate(e2):.2f} | {rate(h2['seconds']):.2f} | **{e2 / h2['seconds']:.2f}x** | "
                f"{rate(p2['seconds']):.2f} | {e2 / p2['seconds']:.2f}x |"
            )
            print(rows[-1], flush=True)
    table = "\n".join(rows)
    differences = "\n".join(notes) if notes else "None."
    text = f"""# Occlusion rays: haarshift against Embree

Written by `python3 benches/compare_rays.py` (see its docstring for what is measured): the
same f32 rays, exported by `tools/measure/src/bin/rays.rs` from haarshift's precomputation, cast by
haarshift and by Embree {getattr(embreex, "__version__", "4.4.0")} through `embreex`
(`rtcOccluded1` per ray, the "Embree 4.4" columns). Rates in millions of rays per second;
haarshift's are its whole precomputation, rays and Haar encoding of the transport, with each
of its ray tracers: "haarshift" is the default where Embree is installed, Embree 3.13.5's
16-wide packets (`rtcOccluded16`, Debian's libembree3), and "our packets" is haarshift's own
tracer, in every build. The ratios are Embree 4.4's time over haarshift's (above 1: haarshift
faster). BVH builds (seconds, Embree 3's / our packets') are not in the rates. Measured in
one run on this 2-core machine (load average {load[0]:.1f}, {load[1]:.1f}, {load[2]:.1f}).

| scene | triangles | vertices | rays (all) | blocked (haarshift / our packets / Embree 4.4) | build s | Embree 4.4, 1 thread | haarshift 1 thread | ratio | our packets 1 thread | ratio | Embree 4.4, 2 processes | haarshift 2 threads | ratio | our packets 2 threads | ratio |
|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|
{table}

Rays answered differently by two of the three, each worked out in f64 against every triangle
to say which answer is exact (for haarshift against Embree 4.4, the first ten listed with the
cosine between the ray and the plane of the triangle Embree finds along it: grazing rays have
a cosine near 0). A scene not listed has the same answers in all three.

{differences}
"""
    (ROOT / "benches" / "rays_results.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
