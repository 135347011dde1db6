#!/usr/bin/env python3
"""Times the haarshift Python package against its peers in one process on this machine.

    pip install ./python opencv-python-headless PyWavelets
    python3 benches/compare_python.py            # runs `cargo bench --bench transform` first
    python3 benches/compare_python.py --no-bench # reuse target/criterion from the last run

Rotation: a 2048 x 2048 float32 image by 30 degrees, same canvas, zero fill, Keys cubic
(a = -0.5, OpenCV's INTER_CUBIC is a = -0.75), against `cv2.warpAffine(INTER_CUBIC)`: one
call that returns a new array (`haarshift.rotate` against `warpAffine` without `dst`), and a
reused rotation writing into one preallocated array (`Rotator.rotate(out=)` against
`warpAffine(dst=)`). Transform: `haarshift.transform` (2048 x 2048 float32, full depth)
against criterion's mean of the Rust `pyramid::forward_into` (benches/transform.rs, the same
array size, preallocated output) and against `pywt.wavedec2(x, "haar",
mode="periodization")`. Call overhead: `haarshift.transform` of a 4 x 4 float32 array, best
of 20 runs of 10,000 calls. Figures are medians of 20 runs after a warm-up (ms).
"""
import argparse
import json
import os
import pathlib
import subprocess
import time
import timeit

import cv2
import numpy as np
import pywt

import haarshift
from compare_rotation import best_time, image  # the rotation bench's image and timing

ROOT = pathlib.Path(__file__).resolve().parent.parent
N = 2048
ANGLE = 30.0


def median_ms(f):
    return best_time(f, 20)


def criterion_ms(group, bench, size):
    path = ROOT / "target" / "criterion" / group / bench / str(size) / "new" / "estimates.json"
    return json.loads(path.read_text())["mean"]["point_estimate"] / 1e6


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--no-bench", action="store_true", help="do not run cargo bench first")
    args = parser.parse_args()
    if not args.no_bench:
        subprocess.run(["cargo", "bench", "--bench", "transform", "--", "pyramid/forward/2048",
                        "--warm-up-time", "1", "--measurement-time", "5"],
                       cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    print(f"haarshift {haarshift.__version__}, OpenCV {cv2.__version__}, PyWavelets {pywt.__version__}, "
          f"numpy {np.__version__}, {cv2.getNumThreads()} OpenCV threads; load average {os.getloadavg()}")
    img = image(N)
    m = cv2.getRotationMatrix2D(((N - 1) / 2, (N - 1) / 2), ANGLE, 1.0)
    dst = np.zeros_like(img)
    rotator = haarshift.Rotator(method="keys")
    rows = []
    cv_new = median_ms(lambda: cv2.warpAffine(img, m, (N, N), flags=cv2.INTER_CUBIC, borderValue=0))
    ours_new = median_ms(lambda: haarshift.rotate(img, ANGLE, method="keys"))
    rows.append(("rotate, new array", ours_new, "cv2.warpAffine cubic", cv_new))
    cv_dst = median_ms(lambda: cv2.warpAffine(img, m, (N, N), dst=dst, flags=cv2.INTER_CUBIC, borderValue=0))
    out = np.zeros_like(img)
    ours_out = median_ms(lambda: rotator.rotate(img, ANGLE, out=out))
    rows.append(("Rotator, out=", ours_out, "cv2.warpAffine cubic, dst=", cv_dst))
    ours_t = median_ms(lambda: haarshift.transform(img))
    rust_t = criterion_ms("pyramid", "forward", N)
    rows.append(("transform", ours_t, "Rust pyramid::forward_into (criterion)", rust_t))
    py_t = median_ms(lambda: pywt.wavedec2(img, "haar", mode="periodization"))
    rows.append(("transform", ours_t, "pywt.wavedec2", py_t))
    tiny = np.ones((4, 4), dtype=np.float32)
    calls = 10_000
    per_call_us = min(timeit.repeat(lambda: haarshift.transform(tiny), number=calls, repeat=20)) / calls * 1e6
    print("| haarshift | ms | baseline | ms | ratio (haarshift / baseline) |")
    print("|---|---|---|---|---|")
    for name, ours, peer, theirs in rows:
        print(f"| {name} | {ours:.2f} | {peer} | {theirs:.2f} | {ours / theirs:.2f}x |")
    print(f"| transform of 4 x 4, per call | {per_call_us:.2f} us | | | |")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
