#!/usr/bin/env python3
"""Make a small run-length-encoded Radiance .hdr test file, and the values it holds.

Usage: make_test_hdr.py IN.hdr OUT.hdr OUT_VALUES.npy FACTOR

Decodes IN (new-style per-channel RLE, as the shared envmaps are; decoder in
downsize_envmap.py), box-filters it by FACTOR x FACTOR, converts each pixel to RGBE the way
Radiance does (frexp of the largest channel: exponent byte e + 128, mantissa bytes
floor(c * m * 256 / max)), and writes it as Radiance writes files: the `#?RADIANCE` header,
`-Y H +X W`, then every scanline as a new-style RLE record (the 2 2 W marker, then each of
the four byte planes as packets: a run of 4 to 127 equal bytes as 128 + count, the byte;
otherwise literals of at most 128 bytes). OUT_VALUES is what a correct decoder reads:
mantissa * 2^(e - 136) per channel (0 where e = 0), little-endian f32 of shape (H, W, 3),
computed from the RGBE bytes, not by decoding OUT. Only numpy is needed. Used once to make
testdata/; the Rust tests never run it.
"""
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from downsize_envmap import read_hdr  # noqa: E402

MIN_RUN = 4


def to_rgbe(rgb):
    """Radiance's float2rgbe, per pixel: bytes (H, W, 4)."""
    peak = rgb.max(axis=2)
    mant, exp = np.frexp(peak)
    out = np.zeros(rgb.shape[:2] + (4,), dtype=np.uint8)
    live = peak > 1e-32
    scale = np.where(live, mant * 256.0 / np.where(live, peak, 1.0), 0.0)
    out[:, :, :3] = np.floor(rgb * scale[:, :, None]).clip(0, 255).astype(np.uint8)
    out[:, :, 3] = np.where(live, exp + 128, 0).astype(np.uint8)
    return out


def from_rgbe(rgbe):
    """What a decoder reads: mantissa * 2^(e - 136), 0 for e = 0."""
    exp = rgbe[:, :, 3].astype(np.int32)
    scale = np.where(exp == 0, 0.0, np.ldexp(1.0, exp - 136))
    return rgbe[:, :, :3].astype(np.float64) * scale[:, :, None]


def encode_plane(values):
    """One byte plane of a scanline as RLE packets."""
    out = bytearray()
    literal = bytearray()
    i, n = 0, len(values)
    while i < n:
        run = 1
        while i + run < n and run < 127 and values[i + run] == values[i]:
            run += 1
        if run >= MIN_RUN:
            for start in range(0, len(literal), 128):
                chunk = literal[start:start + 128]
                out += bytes([len(chunk)]) + chunk
            literal.clear()
            out += bytes([128 + run, values[i]])
            i += run
        else:
            literal.append(values[i])
            i += 1
    for start in range(0, len(literal), 128):
        chunk = literal[start:start + 128]
        out += bytes([len(chunk)]) + chunk
    return bytes(out)


def write_hdr(path, rgbe):
    h, w, _ = rgbe.shape
    assert 8 <= w < 32768, "new-style RLE needs 8 <= width < 32768"
    data = bytearray(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
    data += f"-Y {h} +X {w}\n".encode()
    for y in range(h):
        data += bytes([2, 2, w >> 8, w & 255])
        for ch in range(4):
            data += encode_plane(bytes(rgbe[y, :, ch]))
    open(path, "wb").write(bytes(data))


def main():
    src, dst, values, factor = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
    rgb = read_hdr(src)
    h, w, _ = rgb.shape
    small = rgb.reshape(h // factor, factor, w // factor, factor, 3).mean(axis=(1, 3))
    rgbe = to_rgbe(small)
    write_hdr(dst, rgbe)
    np.save(values, from_rgbe(rgbe).astype("<f4"))


if __name__ == "__main__":
    main()
