"""The error of per-vertex radiance against a reference, relative to the reference's RMS:
RMS over the vertices (and channels) of (render - reference) / RMS of the reference.

    python3 scripts/vertex_error.py REFERENCE.npy RENDER.npy [RENDER.npy ...]

prints one figure per render (%.2e), one line each. Needs numpy.
"""
import sys

import numpy as np


def relative_rms(reference, render):
    ref = np.load(reference).astype(np.float64)
    got = np.load(render).astype(np.float64)
    if ref.shape != got.shape:
        sys.exit(f"{render}: shape {got.shape}, the reference {reference} has {ref.shape}")
    return np.sqrt(((got - ref) ** 2).mean()) / np.sqrt((ref ** 2).mean())


if __name__ == "__main__":
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    for path in sys.argv[2:]:
        print(f"{relative_rms(sys.argv[1], path):.2e}")
