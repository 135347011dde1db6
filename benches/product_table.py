#!/usr/bin/env python3
"""Tables of the product-integral benchmarks (relight/benches/product.rs), with ratios from one run.

Reads criterion's medians (target/criterion/<group>/<method>/<case>/new/estimates.json) and
writes results/product/targets.md and results/product/scaling.md. With --run-cargo it first
runs the bench on one core (RAYON_NUM_THREADS=1) with short measurement times. The machine's
load (from /proc/loadavg) is recorded with the tables.

    python3 benches/product_table.py --run-cargo            # everything, one run
    python3 benches/product_table.py --run-cargo --sizes 32,64 --latlong 64
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
CRIT = ROOT / "target" / "criterion"
OUT = ROOT / "results" / "product"


def median_ns(group, method, case):
    path = CRIT / group / method / case / "new" / "estimates.json"
    if not path.exists():
        return None
    return json.loads(path.read_text())["median"]["point_estimate"]


def fmt(ns):
    if ns is None:
        return "-"
    if ns < 1e3:
        return f"{ns:.0f} ns"
    if ns < 1e6:
        return f"{ns / 1e3:.2f} us"
    return f"{ns / 1e6:.2f} ms"


def ratio(a, b):
    return "-" if a is None or b is None else f"{b / a:.1f}x"


def targets_table():
    lines = ["| channels | kept (transport / envmap / Phong) | triple (sparse) | general N=3 | dense O(M) | pixel, stored maps | target |",
             "|---|---|---|---|---|---|---|"]
    target = {"200-70-70_total": "< 5 us", "200-70-70_per_face": "< 30 us", "full": "dense < 30 us"}
    kept = {"200-70-70_total": "200 / 70 / 70 in all", "200-70-70_per_face": "200 / 70 / 70 per face (1200 / 420 / 420)",
            "full": "all (24,576 each)"}
    for label in ["mono", "rgb"]:
        group = f"targets_{label}"
        for case in ["200-70-70_total", "200-70-70_per_face", "full"]:
            row = [median_ns(group, m, case) for m in ["triple", "general", "dense", "pixel_stored"]]
            lines.append(f"| {'1' if label == 'mono' else '3 (RGB)'} | {kept[case]} | " + " | ".join(fmt(v) for v in row)
                         + f" | {target[case]} |")
    return "\n".join(lines)


def scaling_table(params):
    lines = ["| map | N | kept | tree | pixel (inverse incl.) | pairwise | pixel (stored maps) | pixel-inverse / tree | pairwise / tree | pixel-stored / tree |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for kind, s in params:
        group = f"scaling_{kind}{s}"
        label = f"cube 6 x {s}^2" if kind == "cube" else f"lat-long {s} x {2 * s}"
        stored = {n: median_ns(group, "pixel_stored", f"N{n}_keep100") for n in range(3, 7)}
        for n in range(3, 7):
            for p in [1, 5, 10, 100]:
                case = f"N{n}_keep{p}"
                tree, inv, pair = (median_ns(group, m, case) for m in ["tree", "pixel_inverse", "pairwise"])
                if tree is None:
                    continue
                lines.append(f"| {label} | {n} | {p} % | {fmt(tree)} | {fmt(inv)} | {fmt(pair)} | {fmt(stored[n])} | "
                             f"{ratio(tree, inv)} | {ratio(tree, pair)} | {ratio(tree, stored[n])} |")
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--run-cargo", action="store_true")
    ap.add_argument("--sizes", default="32,64,128,256", help="cube face sides S (6 x S^2)")
    ap.add_argument("--latlong", default="64,128,256", help="lat-long heights H (H x 2H)")
    ap.add_argument("--skip-targets", action="store_true")
    args = ap.parse_args()
    params = [("cube", int(s)) for s in args.sizes.split(",") if s] + [("latlong", int(h)) for h in args.latlong.split(",") if h]
    load_before = open("/proc/loadavg").read().split()[:3]
    if args.run_cargo:
        env = dict(os.environ, RAYON_NUM_THREADS="1", PRODUCT_BENCH_SIZES=args.sizes, PRODUCT_BENCH_LATLONG=args.latlong)
        # Short groups: the bench sets its own sample counts and measurement times.
        filt = "scaling" if args.skip_targets else "targets|scaling"
        subprocess.run(["cargo", "bench", "-p", "haarshift-relight", "--bench", "product", "--", filt], cwd=ROOT, env=env, check=True)
    load_after = open("/proc/loadavg").read().split()[:3]
    OUT.mkdir(parents=True, exist_ok=True)
    note = (f"Criterion medians, f32, one core (RAYON_NUM_THREADS=1), on a 2-core machine shared with other jobs: "
            f"load average {' '.join(load_before)} before and {' '.join(load_after)} after the run. "
            f"Made by `python3 benches/product_table.py {' '.join(sys.argv[1:])}`"
            + (" (the targets table then reads the medians of the latest `targets` run)" if args.skip_targets else "")
            + ".\n")
    (OUT / "targets.md").write_text("# Product integral speed targets (6 x 64^2 cube map, real data)\n\n" + note + "\n"
                                    + targets_table() + "\n")
    (OUT / "scaling.md").write_text("# Tree product integral against the pixel domain and pairwise products\n\n" + note + "\n"
                                    + scaling_table(params) + "\n")
    print(targets_table())
    print()
    print(scaling_table(params))


if __name__ == "__main__":
    main()
