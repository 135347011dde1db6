import os
from typing import Literal, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import relight as relight
from . import sphere as sphere

__version__: str

ArrayLike = npt.ArrayLike
Method = Literal[
    "nearest", "linear", "keys", "bspline3", "bspline5", "lanczos3", "lanczos4", "fft", "haar"
]
Boundary = Literal["zero", "edge", "reflect", "wrap"]
Levels = Union[int, Literal["full"], None]

def transform(
    image: ArrayLike,
    *,
    layout: Literal["pyramid", "separable"] = "pyramid",
    normalization: Literal["average", "orthonormal"] = "average",
    levels: Levels = None,
    padding: Boundary = "zero",
) -> np.ndarray:
    """The 2D Haar transform of an (H, W) or (H, W, C) image, padded to powers of two."""

def inverse(
    coefficients: ArrayLike,
    *,
    layout: Literal["pyramid", "separable"] = "pyramid",
    normalization: Literal["average", "orthonormal"] = "average",
    levels: Levels = None,
    shape: Optional[Tuple[int, int]] = None,
) -> np.ndarray:
    """The image whose transform `coefficients` are, cropped to `shape` if given."""

def shift(
    image: ArrayLike,
    dx: float,
    dy: float = 0.0,
    *,
    method: Method = "haar",
    precision: Optional[int] = None,
    retain: bool = False,
    keys_a: Optional[float] = None,
    boundary: Boundary = "wrap",
) -> np.ndarray:
    """The image moved by dx columns (right) and dy rows (down): out[r, c] = image[r - dy, c - dx]."""

def rotate(
    image: ArrayLike,
    angle: float,
    *,
    method: Method = "bspline3",
    precision: Optional[int] = None,
    retain: bool = False,
    keys_a: Optional[float] = None,
    canvas: Literal["same", "expand"] = "same",
    fill: Optional[float] = None,
    boundary: Optional[Boundary] = None,
    supersample: int = 0,
) -> np.ndarray:
    """The image turned counter-clockwise (as displayed) by `angle` degrees with three shears."""

class Rotator:
    """A rotation kept for repeated calls, with its own intermediate images."""

    def __init__(
        self,
        *,
        method: Method = "bspline3",
        precision: Optional[int] = None,
        retain: bool = False,
        keys_a: Optional[float] = None,
        canvas: Literal["same", "expand"] = "same",
        fill: Optional[float] = None,
        boundary: Optional[Boundary] = None,
        supersample: int = 0,
    ) -> None: ...
    def rotate(
        self, image: ArrayLike, angle: float, *, out: Optional[np.ndarray] = None
    ) -> np.ndarray:
        """`image` turned by `angle` degrees; written into `out` when given."""
    def __call__(
        self, image: ArrayLike, angle: float, *, out: Optional[np.ndarray] = None
    ) -> np.ndarray: ...

def read_image(path: Union[str, "os.PathLike[str]"]) -> np.ndarray:
    """An image file (PNG, JPEG, TIFF, OpenEXR, .hdr, .npy) as (H, W) or (H, W, C)."""

def write_image(
    path: Union[str, "os.PathLike[str]"],
    image: ArrayLike,
    *,
    force: bool = False,
    depth: Optional[Literal["u8", "u16", "f16", "f32", "f64"]] = None,
) -> None:
    """Writes `image` atomically in the format the extension names."""


