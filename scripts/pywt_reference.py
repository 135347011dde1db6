#!/usr/bin/env python3
"""Generate the PyWavelets reference arrays in testdata/pywt/ (run once; tests need no Python).

For each case it writes `<case>_input.npy` (f64) and `<case>_pywt.npy`: the output of
`pywt.wavedec2(x, 'haar', mode='periodization', level=K)` placed in haarshift's Mallat layout
with the band mapping measured on PyWavelets 1.8:

    pywt cA -> scaling block A          (orthonormal, same sign and scale)
    pywt cH -> b (vertical: top minus bottom), below the level's approximation
    pywt cV -> a (horizontal: left minus right), right of the level's approximation
    pywt cD -> c (diagonal), diagonally

The level count K is stored in the file name. Usage: python3 scripts/pywt_reference.py
"""
import pathlib

import numpy as np
import pywt
from PIL import Image

OUT = pathlib.Path(__file__).resolve().parent.parent / "testdata" / "pywt"


def mallat(coeffs):
    """Place wavedec2 output (coarsest first) into one array, haarshift's layout."""
    ca = coeffs[0]
    h0, w0 = ca.shape
    k = len(coeffs) - 1
    out = np.zeros((h0 << k, w0 << k))
    out[:h0, :w0] = ca
    for level, (ch, cv, cd) in enumerate(coeffs[1:]):
        bh, bw = h0 << level, w0 << level
        assert ch.shape == (bh, bw)
        out[:bh, bw:2 * bw] = cv
        out[bh:2 * bh, :bw] = ch
        out[bh:2 * bh, bw:2 * bw] = cd
    return out


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(20081122)
    camera = np.asarray(Image.open(OUT.parent / "camera.png"), dtype=np.float64)
    cases = {
        "random16x16": (rng.normal(size=(16, 16)) * 40.0, 4),
        "random32x64": (rng.uniform(-1.0, 1.0, size=(32, 64)), 5),
        "random64x64_partial": (rng.normal(size=(64, 64)), 3),
        "camera128": (camera[192:320, 192:320], 7),
    }
    for name, (x, levels) in cases.items():
        coeffs = pywt.wavedec2(x, "haar", mode="periodization", level=levels)
        np.save(OUT / f"{name}_input.npy", x)
        np.save(OUT / f"{name}_levels{levels}_pywt.npy", mallat(coeffs))
        print(name, x.shape, levels)


if __name__ == "__main__":
    main()
