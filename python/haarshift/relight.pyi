import os
from typing import Literal, Optional, Union

import numpy as np
import numpy.typing as npt

def scene(
    scene: Union[str, "os.PathLike[str]"],
    *,
    env: Union[str, "os.PathLike[str]", npt.ArrayLike, None] = None,
    yaw: Optional[float] = None,
    pitch: Optional[float] = None,
    roll: Optional[float] = None,
    method: Literal["haar", "reference"] = "haar",
    param: Literal["latlong", "cube"] = "latlong",
    resolution: int = 32,
    keep_light: Optional[int] = None,
    keep_visibility: Optional[int] = None,
    keep_field: Optional[int] = None,
    circles: int = 100,
    circle_points: int = 200,
    shells: int = 20,
    shell_grid: int = 9,
) -> np.ndarray:
    """Every vertex's outgoing radiance (V, 3) of the scene file as placed."""
