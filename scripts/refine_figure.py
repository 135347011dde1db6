#!/usr/bin/env python3
"""The figure of scripts/refine.sh: the same crop (the bunny's shadow) of a truth and of
each run's render, and below each render its absolute error against the truth (4x), as one
PNG. Reads WORK/TRUTH.exr and WORK/RUN.exr, converted to arrays by haarshift's own
`transform` and `inverse` (no EXR reader is needed); numpy and zlib only.

    python3 scripts/refine_figure.py WORK OUT.png TRUTH RUN...
"""
import struct
import subprocess
import sys
import zlib

import numpy as np

HS = "target/release/haarshift"
# The crop, rows and columns of the 640 x 480 default view: the shadow's far end on the ground.
ROWS, COLS = slice(250, 360), slice(300, 540)


def image(work, name):
    """WORK/NAME.exr as an (H, W, 3) float array, through a Haar round trip (exact to f32)."""
    coefficients, pixels = f"{work}/{name}-c.npy", f"{work}/{name}-p.npy"
    for args in (
        ["transform", f"{work}/{name}.exr", "-o", coefficients],
        ["inverse", coefficients, "-o", pixels, "--depth", "f32"],
    ):
        subprocess.run([HS, *args], check=True, capture_output=True)
    a = np.load(pixels).astype(np.float64)
    return a if a.shape[-1] == 3 else np.moveaxis(a, 0, -1)


def srgb(x):
    x = np.clip(x, 0, 1)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)


def write_png(path, rgb):
    """An 8-bit RGB PNG of an (H, W, 3) array in [0, 1]."""
    h, w, _ = rgb.shape
    raw = np.round(rgb * 255).astype(np.uint8)
    rows = b"".join(b"\0" + raw[y].tobytes() for y in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    with open(path, "wb") as out:
        out.write(b"\x89PNG\r\n\x1a\n")
        out.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        out.write(chunk(b"IDAT", zlib.compress(rows, 9)))
        out.write(chunk(b"IEND", b""))


def main():
    work, out, truth_name, runs = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:]
    truth = image(work, truth_name)[ROWS, COLS]
    gap = np.ones((truth.shape[0], 4, 3))
    top, bottom = [srgb(truth)], [np.zeros_like(truth)]
    for r in runs:
        render = image(work, r)[ROWS, COLS]
        top.append(srgb(render))
        bottom.append(srgb(4 * np.abs(render - truth)))
    join = lambda panels: np.concatenate([x for p in panels for x in (p, gap)][:-1], axis=1)
    band = np.ones((4, join(top).shape[1], 3))
    write_png(out, np.concatenate([join(top), band, join(bottom)], axis=0))
    print(f"Panels, left to right: {truth_name}, {', '.join(runs)}.")


if __name__ == "__main__":
    main()
