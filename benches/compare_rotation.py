#!/usr/bin/env python3
"""Times haarshift's three-shear rotation against OpenCV and scipy on this machine.

Rotates the same kind of 2048x2048 (and 512x512) float32 image by 30 degrees, same canvas, zero
fill: OpenCV `warpAffine` (INTER_CUBIC, INTER_LANCZOS4) and `scipy.ndimage.rotate(order=3,
reshape=False)`, then haarshift per kernel from criterion's saved estimates
(target/criterion/rotate/<kernel>/<n>/new/estimates.json). With --run-cargo it first runs
`cargo bench --bench rotate` briefly. Python is only for this comparison; the library and its
tests never need it.

    pip install --user numpy scipy opencv-python-headless
    python3 benches/compare_rotation.py --run-cargo
"""

import argparse
import json
import os
import pathlib
import subprocess
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
KERNELS = ["nearest", "linear", "keys", "bspline3", "bspline5", "lanczos3", "lanczos4", "fft", "haar"]
ANGLE = 30.0


def image(n):
    # The same image as benches/rotate.rs.
    y, x = np.mgrid[0:n, 0:n].astype(np.float32) / np.float32(n)
    return (np.sin(40 * x * y) + 0.5 * np.cos(13 * x - 7 * y)).astype(np.float32)


def best_time(f, repeats):
    """Median of `repeats` runs after one warm-up, in milliseconds."""
    f()
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append((time.perf_counter() - t) * 1e3)
    return float(np.median(times))


def python_baselines(n, repeats):
    import cv2
    from scipy import ndimage

    img = image(n)
    # OpenCV's angle is counter-clockwise as displayed, like haarshift's.
    m = cv2.getRotationMatrix2D(((n - 1) / 2, (n - 1) / 2), ANGLE, 1.0)
    # Every call writes into one preallocated array, as the haarshift bench does.
    dst = np.zeros_like(img)
    out = {}
    for name, flag in [("opencv cubic", cv2.INTER_CUBIC), ("opencv lanczos4", cv2.INTER_LANCZOS4)]:
        out[name] = best_time(
            lambda: cv2.warpAffine(img, m, (n, n), dst=dst, flags=flag, borderValue=0), repeats
        )
    out["scipy order=3"] = best_time(
        lambda: ndimage.rotate(img, ANGLE, reshape=False, order=3, mode="constant", output=dst),
        max(3, repeats // 4),
    )
    return out


def haarshift_times(n):
    out = {}
    runs = [("rotate", k, k) for k in KERNELS] + [("rotate_one_shot", "keys", "keys one-shot")]
    for group, k, label in runs:
        path = ROOT / "target" / "criterion" / group / k / str(n) / "new" / "estimates.json"
        if path.exists():
            est = json.loads(path.read_text())
            out[label] = est["median"]["point_estimate"] / 1e6
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--run-cargo", action="store_true", help="run the criterion bench first")
    ap.add_argument("--sizes", default="512,2048")
    ap.add_argument("--repeats", type=int, default=20)
    args = ap.parse_args()
    sizes = [int(s) for s in args.sizes.split(",")]
    if args.run_cargo:
        subprocess.run(
            ["cargo", "bench", "--bench", "rotate", "--", "--warm-up-time", "1",
             "--measurement-time", "3"],
            cwd=ROOT,
            check=True,
        )
    print(f"load average before the Python baselines: {os.getloadavg()}")
    print("\n| size | method | ms | vs OpenCV cubic | vs OpenCV Lanczos-4 | vs scipy order=3 |")
    print("|---|---|---|---|---|---|")
    for n in sizes:
        base = python_baselines(n, args.repeats)
        ours = haarshift_times(n)
        if not ours:
            print(f"(no criterion results for {n}: run with --run-cargo)")
        for name, ms in base.items():
            print(f"| {n}^2 | {name} | {ms:.2f} | | | |")
        for k, ms in ours.items():
            print(
                f"| {n}^2 | haarshift {k} | {ms:.2f} | {ms / base['opencv cubic']:.2f}x"
                f" | {ms / base['opencv lanczos4']:.2f}x"
                f" | {base['scipy order=3'] / ms:.1f}x faster |"
            )
    print(f"\nload average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
