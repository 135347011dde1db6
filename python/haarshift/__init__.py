"""haarshift: signal processing in the Haar wavelet domain, on numpy arrays.

The Rust library's transforms, shifts, rotations, spherical-map rotations and product
integrals, with the command line's vocabulary: the same method names, defaults and messages.
Arrays are (H, W) or (H, W, C); float32 and float64 come back in their own dtype, uint8 and
uint16 are computed in float32 in their code units. Long calls release the GIL. Errors are
ValueError (bad arguments or arrays), OSError (files) and MemoryError (work beyond the memory
budget), each with the library's one-line message.

>>> import numpy as np, haarshift
>>> x = np.arange(16.0).reshape(4, 4)
>>> c = haarshift.transform(x)
>>> bool((haarshift.inverse(c) == x).all())
True
"""
from . import relight, sphere
from ._native import (
    Rotator,
    __version__,
    inverse,
    read_image,
    rotate,
    shift,
    transform,
    write_image,
)

__all__ = [
    "Rotator",
    "__version__",
    "inverse",
    "read_image",
    "relight",
    "rotate",
    "shift",
    "sphere",
    "transform",
    "write_image",
]
