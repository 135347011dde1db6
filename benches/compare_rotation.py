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
import pathlib
import subprocess
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
KERNELS = ["nearest", "linear", "keys", "bspline3", "bspline5", "lanczos3", "lanczos4", "fft"]
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
    out = {}
    for name, flag in [("opencv cubic", cv2.INTER_CUBIC), ("opencv lanczos4", cv2.INTER_LANCZOS4)]:
        out[name] = best_time(
            lambda: cv2.warpAffine(img, m, (n, n), flags=flag, borderValue=0), repeats
        )
    out["scipy order=3"] = best_time(
        lambda: ndimage.rotate(img, ANGLE, reshape=False, order=3, mode="constant"),
        max(3, repeats // 4),
    )
    return out


def haarshift_times(n):
    out = {}
    for k in KERNELS:
        path = ROOT / "target" / "criterion" / "rotate" / k / str(n) / "new" / "estimates.json"
        if path.exists():
            est = json.loads(path.read_text())
            out[k] = est["median"]["point_estimate"] / 1e6
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
    for n in sizes:
        base = python_baselines(n, args.repeats)
        ours = haarshift_times(n)
        print(f"\n{n}x{n} float32, rotate {ANGLE} degrees (median ms)")
        for name, ms in base.items():
            print(f"  {name:18s} {ms:9.2f}")
        print(f"  {'haarshift':18s} {'ms':>9s}  vs opencv cubic  vs opencv lanczos4  vs scipy order=3")
        for k, ms in ours.items():
            print(
                f"  {k:18s} {ms:9.2f}  {ms / base['opencv cubic']:14.2f}x"
                f"  {ms / base['opencv lanczos4']:17.2f}x  {base['scipy order=3'] / ms:13.1f}x faster"
            )
        if not ours:
            print("  (no criterion results: run with --run-cargo)")


if __name__ == "__main__":
    main()
