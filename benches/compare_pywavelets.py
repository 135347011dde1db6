#!/usr/bin/env python3
"""Time haarshift's 2D pyramid transform and PyWavelets on this machine in one run; print ratios.

    pip install pywavelets numpy
    python3 benches/compare_pywavelets.py            # runs `cargo bench --bench transform` first
    python3 benches/compare_pywavelets.py --no-bench # reuse target/criterion from the last run

haarshift: criterion's mean of `pyramid::forward_into` / `inverse_into` (f32, full depth,
preallocated output) and of a plain single-threaded copy of the same array.
PyWavelets: best of 20 calls of `wavedec2(x, 'haar', mode='periodization')` / `waverec2` on a
float32 array (full depth).
"""
import argparse
import json
import pathlib
import subprocess
import timeit

import numpy as np
import pywt

ROOT = pathlib.Path(__file__).resolve().parent.parent


def criterion_ms(bench, size):
    path = ROOT / "target" / "criterion" / "pyramid" / bench / str(size) / "new" / "estimates.json"
    return json.loads(path.read_text())["mean"]["point_estimate"] / 1e6


def best_ms(fn, repeat=20):
    return min(timeit.repeat(fn, number=1, repeat=repeat)) * 1e3


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--no-bench", action="store_true", help="do not run cargo bench first")
    args = parser.parse_args()
    if not args.no_bench:
        subprocess.run(["cargo", "bench", "--bench", "transform", "--", "--warm-up-time", "1",
                        "--measurement-time", "5"], cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    print(f"PyWavelets {pywt.__version__}, numpy {np.__version__}")
    print("| size | op | haarshift ms | copy ms | haarshift / copy | PyWavelets ms | PyWavelets / haarshift |")
    print("|---|---|---|---|---|---|---|")
    for size in (512, 2048):
        x = (np.arange(size * size, dtype=np.float32).reshape(size, size) % 255).astype(np.float32)
        coeffs = pywt.wavedec2(x, "haar", mode="periodization")
        py = {
            "forward": best_ms(lambda: pywt.wavedec2(x, "haar", mode="periodization")),
            "inverse": best_ms(lambda: pywt.waverec2(coeffs, "haar", mode="periodization")),
        }
        copy = criterion_ms("copy", size)
        for op in ("forward", "inverse"):
            ours = criterion_ms(op, size)
            print(f"| {size}x{size} | {op} | {ours:.3f} | {copy:.3f} | {ours / copy:.2f} | {py[op]:.1f} | {py[op] / ours:.0f}x |")


if __name__ == "__main__":
    main()
