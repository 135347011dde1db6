#!/usr/bin/env python3
"""results/relight/mitsuba.md: haarshift's per-vertex radiance against Mitsuba 3.

For each scene (the bunny, the bunny on its ground, the bunny in the open box) and map, the
truth is tools/mitsuba/vertex_radiance.py on the same vertices (K at random, the same for every
row) at 0 to B bounces; haarshift's is `relight precompute` at lat-long N with `--bounces b`,
shaded by the Python package. Each row gives the relative RMS, Mitsuba's noise taken out
(sqrt(max(0, mean err^2 - mean se^2)) / RMS of the truth), of the direct light, of the total,
and of the bounced part alone (total minus direct; relative to the bounced part's RMS), over
all chosen vertices and over the contact vertices (creases) apart, with the noise beside it.

Resumable: every cache and every Mitsuba estimate is kept under the work folder and reused.

    python3 scripts/mitsuba_table.py [--vertices 100] [--strata 64] [--work target/mitsuba]
"""
import argparse
import importlib.util
import os
import pathlib
import subprocess
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
spec = importlib.util.spec_from_file_location("vertex_radiance",
                                              ROOT / "tools" / "mitsuba" / "vertex_radiance.py")
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)

SCENES = {
    "bunny": (["testdata/meshes/bunny.ply"], []),
    "bunny on its ground": (["testdata/meshes/bunny.ply"], ["--ground-plane"]),
    "bunny in the open box": (["testdata/scenes/bunny_in_box.json"], []),
}
MAPS = {"venice_sunset": "testdata/envmaps/venice_sunset_1k.hdr",
        "rooitou_park": "testdata/envmaps/rooitou_park_1k.hdr"}


def binary():
    return ROOT / "target" / "release" / "haarshift"


def cache(work, scene, resolution, bounces, samples):
    sources, flags = SCENES[scene]
    path = work / f"{scene.replace(' ', '_')}_{resolution}_{bounces}_{samples}.hsr"
    if not path.exists():
        subprocess.run([str(binary()), "relight", "precompute", *sources, *flags, "--param",
                        "latlong", "--resolution", str(resolution), "--bounces", str(bounces),
                        "--visibility-samples", str(samples), "-o", str(path)],
                       check=True, cwd=ROOT, capture_output=True)
    return path


def shade(path, env):
    import haarshift
    radiance, _ = haarshift.relight.Shader(haarshift.relight.Cache.read(str(path))).shade(env)
    return np.asarray(radiance, dtype=np.float64)


def truth(work, scene, map_name, bounces, chosen, strata, reference_cache):
    path = work / f"mitsuba_{scene.replace(' ', '_')}_{map_name}_{bounces}_{strata}.npz"
    if not path.exists():
        tool.main([str(reference_cache), str(ROOT / MAPS[map_name]), "-o", str(path),
                   "--bounces", str(bounces), "--strata", str(strata), "--vertices",
                   str(len(chosen)), "--seed", "11", "--force"])
    data = np.load(path)
    assert np.array_equal(data["vertices"], chosen)
    return data


def rel(ours, want, se):
    """(noise taken out, raw, noise), each relative to the truth's RMS."""
    raw = np.mean((ours - want) ** 2)
    noise = np.mean(se ** 2)
    scale = np.sqrt(np.mean(want ** 2))
    return tuple(float(x) / scale for x in (np.sqrt(max(raw - noise, 0.0)), np.sqrt(raw),
                                           np.sqrt(noise)))


def cell(values):
    bias, raw, noise = values
    return f"{bias:.2%} ({raw:.2%}; {noise:.2%})"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--vertices", type=int, default=100)
    ap.add_argument("--strata", type=int, default=64)
    ap.add_argument("--resolutions", default="16,32,64,128")
    ap.add_argument("--bounces", type=int, default=3)
    ap.add_argument("--bounce-resolution", type=int, default=64)
    ap.add_argument("--samples", type=int, default=1, help="--visibility-samples")
    ap.add_argument("--maps", default="venice_sunset,rooitou_park")
    ap.add_argument("--work", default="target/mitsuba")
    ap.add_argument("-o", "--output", default="results/relight/mitsuba.md")
    args = ap.parse_args()
    work = ROOT / args.work
    work.mkdir(parents=True, exist_ok=True)
    resolutions = [int(r) for r in args.resolutions.split(",")]
    lines = [
        "# haarshift against Mitsuba 3",
        "",
        "Made by `python3 scripts/mitsuba_table.py " + " ".join(sys.argv[1:]) + "` (Mitsuba "
        f"3, `scalar_rgb`; {args.vertices} vertices at random a scene, {args.strata}^2 "
        "directions each; `--visibility-samples " + str(args.samples) + "`). Each cell: the "
        "relative RMS difference with Mitsuba's noise taken out (sqrt(max(0, mean err^2 - "
        "mean se^2)) over the truth's RMS), then in brackets the raw relative RMS and the "
        "noise (Mitsuba's standard error, relative, which overstates a stratified estimate's: "
        "a 0.00% means the difference is within the noise). "
        "'bounced' is the bounced part alone, relative to its own RMS; 'creases' are the "
        "contact vertices of `relight::precompute::origin` among the chosen ones.",
        "",
        "| scene | map | lat-long | bounces | direct | total | bounced | creases: total |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for scene in SCENES:
        for map_name in args.maps.split(","):
            env = str(ROOT / MAPS[map_name])
            reference = cache(work, scene, 16, 0, 1)
            n = tool.read_cache(str(reference))[0].shape[0]
            chosen = tool.choose(args.vertices, n, 11)
            direct_truth = truth(work, scene, map_name, 0, chosen, args.strata, reference)
            contact = direct_truth["contact"]
            d_want, d_se = direct_truth["direct"], direct_truth["direct_se"]
            rows = [(r, 0) for r in resolutions]
            rows += [(args.bounce_resolution, b) for b in range(1, args.bounces + 1)]
            for resolution, bounces in rows:
                ours = shade(cache(work, scene, resolution, bounces, args.samples), env)[chosen]
                direct = shade(cache(work, scene, resolution, 0, args.samples), env)[chosen]
                cells = [cell(rel(direct, d_want, d_se))]
                if bounces == 0:
                    cells += ["", "", ""]
                else:
                    t = truth(work, scene, map_name, bounces, chosen, args.strata, reference)
                    want = t["direct"] + t["bounced"]
                    se = np.hypot(t["direct_se"], t["bounced_se"])
                    cells += [cell(rel(ours, want, se)),
                              cell(rel(ours - direct, t["bounced"], t["bounced_se"]))]
                    if contact.any():
                        c = rel(ours[contact], want[contact], se[contact])
                        cells.append(f"{cell(c)}, {int(contact.sum())} vertices")
                    else:
                        cells.append("none chosen")
                lines.append(f"| {scene} | {map_name} | {resolution} | {bounces} | "
                             + " | ".join(cells) + " |")
                print(lines[-1], flush=True)
    lines += [
        "",
        "Before the crease contract and the one-sided rule (issue 63, measured by the same "
        "method at 16,384 directions on 300 vertices), the box scene's direct light was 21%, "
        "19% and 19% off at lat-long 16, 32 and 128, every vertex counted: its crease vertices "
        "were black (Embree) or lit at random (our packets). The truth's noise here bounds what "
        "these rows can show: differences below about the bracketed noise are not resolved; "
        "more directions (`--strata`) resolve them, at Mitsuba's scalar speed (about a minute a "
        "scene and bounce count at the defaults on 2 cores).",
    ]
    out = ROOT / args.output
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_suffix(".tmp")
    tmp.write_text("\n".join(lines) + "\n")
    os.replace(tmp, out)
    print(out)


if __name__ == "__main__":
    main()
