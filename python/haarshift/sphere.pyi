from typing import Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

Keep = Union[int, Sequence[int], None]

def rotate(
    map: npt.ArrayLike,
    yaw: float = 0.0,
    pitch: float = 0.0,
    roll: float = 0.0,
    *,
    method: Literal["haar", "haar-cubic", "bilinear", "bicubic", "reference"] = "haar",
    level: Optional[int] = None,
    samples: int = 8,
) -> np.ndarray:
    """The lat-long map rotated, g(p) = f(R p), R = Rz(roll) Ry(yaw) Rx(pitch), degrees."""

def integrate(
    maps: Sequence[npt.ArrayLike],
    *,
    param: Literal["latlong", "cube"] = "latlong",
    resolution: Optional[int] = None,
    keep: Keep = None,
    threshold: Optional[float] = None,
    per_face: bool = False,
    depth: Optional[int] = None,
    method: Literal["tree", "triple", "pixel", "pairwise"] = "tree",
) -> Union[float, np.ndarray]:
    """The integral over the sphere of the product of the maps, on their Haar trees."""

def product(
    maps: Sequence[npt.ArrayLike],
    *,
    param: Literal["latlong", "cube"] = "latlong",
    resolution: Optional[int] = None,
    keep: Keep = None,
    threshold: Optional[float] = None,
    per_face: bool = False,
) -> np.ndarray:
    """The product of the maps through their Haar trees."""
