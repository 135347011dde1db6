#!/usr/bin/env python3
"""Make the small test copy of a Radiance .hdr lat-long map.

Usage: downsize_envmap.py IN.hdr OUT.npy FACTOR

Decodes the RGBE file (new-style per-channel RLE, value = mantissa * 2^(exp-136), as
stb_image and the `image` crate do), box-filters it by FACTOR x FACTOR (a plain mean of each
block of pixels, so every row band keeps its mean and the solid-angle weighted energy is
preserved to within the change of the sin(theta) weight inside a block), and writes a
little-endian f32 array of shape (H, W, 3), C order. Only numpy is needed. Used once to make
testdata/; the Rust tests never run it.
"""
import sys

import numpy as np


def read_hdr(path):
    data = open(path, "rb").read()
    pos = 0
    width = height = None
    while True:
        end = data.index(b"\n", pos)
        line = data[pos:end].decode("ascii", "replace")
        pos = end + 1
        if line.startswith("-Y "):
            parts = line.split()
            height, width = int(parts[1]), int(parts[3])
            break
    img = np.zeros((height, width, 4), dtype=np.uint8)
    for y in range(height):
        head = data[pos:pos + 4]
        if head[0] != 2 or head[1] != 2:
            raise ValueError("only new-style RLE scanlines are supported")
        pos += 4
        for ch in range(4):
            x = 0
            while x < width:
                count = data[pos]
                pos += 1
                if count > 128:
                    count -= 128
                    img[y, x:x + count, ch] = data[pos]
                    pos += 1
                else:
                    img[y, x:x + count, ch] = np.frombuffer(data[pos:pos + count], np.uint8)
                    pos += count
                x += count
    mant = img[:, :, :3].astype(np.float64)
    exp = img[:, :, 3].astype(np.int32)
    scale = np.where(exp == 0, 0.0, np.ldexp(1.0, exp - 136))
    return mant * scale[:, :, None]


def main():
    src, dst, factor = sys.argv[1], sys.argv[2], int(sys.argv[3])
    rgb = read_hdr(src)
    h, w, _ = rgb.shape
    small = rgb.reshape(h // factor, factor, w // factor, factor, 3).mean(axis=(1, 3))
    np.save(dst, small.astype("<f4"))
    lum = rgb @ np.array([0.2126, 0.7152, 0.0722])
    y, x = np.unravel_index(np.argmax(lum), lum.shape)
    print(f"{src}: {w}x{h}, max luminance {lum.max():.1f} at (x={x}, y={y}); wrote {dst} "
          f"{small.shape}")


if __name__ == "__main__":
    main()
