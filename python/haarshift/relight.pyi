import os
from typing import Dict, Literal, Optional, Sequence, Tuple, Union, overload

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

class Cache:
    """A precomputed scene: mesh, albedo and every vertex's transport (an `.hsr` file)."""

    @staticmethod
    def read(path: Union[str, "os.PathLike[str]"]) -> "Cache": ...
    def write(self, path: Union[str, "os.PathLike[str]"], *, force: bool = False) -> int: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def object_vertices(self) -> int: ...
    @property
    def positions(self) -> np.ndarray: ...
    @property
    def normals(self) -> np.ndarray: ...
    @property
    def triangles(self) -> np.ndarray: ...
    @property
    def albedo(self) -> np.ndarray: ...
    @property
    def param(self) -> Tuple[str, int]: ...
    @property
    def sh_bands(self) -> Optional[int]: ...
    @property
    def bounces(self) -> int: ...

@overload
def precompute(
    scene: Union[str, "os.PathLike[str]"],
    *,
    output: Union[str, "os.PathLike[str]", None] = None,
    param: Literal["latlong", "cube"] = "latlong",
    resolution: int = 32,
    keep_visibility: Optional[int] = None,
    visibility_samples: int = 1,
    seed: int = 0,
    ray_tracer: Optional[Literal["embree", "packets"]] = None,
    map_size: int = 2048,
    sh_bands: Optional[int] = None,
    force: bool = False,
    ground_plane: bool = False,
    ground_cells: Optional[int] = None,
    memory_limit: Union[int, str, None] = None,
    order: Literal["vertex", "direction"] = "vertex",
    bounces: int = 0,
    refine: Optional[float] = None,
    max_vertices: Optional[int] = None,
    refine_light: Union[str, "os.PathLike[str]", None] = None,
    shard: None = None,
    shards: None = None,
    bounce_from: None = None,
) -> Cache:
    """Precomputes a mesh or scene file as `haarshift relight precompute` does: every keyword
    is the command line's flag of the same name."""

@overload
def precompute(
    scene: Union[str, "os.PathLike[str]"],
    *,
    output: Union[str, "os.PathLike[str]"],
    param: Literal["latlong", "cube"] = "latlong",
    resolution: int = 32,
    keep_visibility: Optional[int] = None,
    visibility_samples: int = 1,
    seed: int = 0,
    ray_tracer: Optional[Literal["embree", "packets"]] = None,
    map_size: int = 2048,
    sh_bands: Optional[int] = None,
    force: bool = False,
    ground_plane: bool = False,
    ground_cells: Optional[int] = None,
    memory_limit: Union[int, str, None] = None,
    order: Literal["vertex"] = "vertex",
    bounces: int = 0,
    bounce_from: Union[str, "os.PathLike[str]", None] = None,
    shard: Union[str, Tuple[int, int]],
    shards: Optional[int] = None,
) -> str:
    """Precomputes shard `"i/n"` (or `"auto"`, or `(i, n)`) into `output` (skipped when it is
    there, complete); returns the path."""

def merge(
    shards: Sequence[Union[str, "os.PathLike[str]"]],
    *,
    output: Union[str, "os.PathLike[str]", None] = None,
    force: bool = False,
) -> Cache:
    """Merges shards into the cache an unsharded `precompute` makes (written to `output`)."""

class Shader:
    """Per-vertex shading of a cache, built once from `relight render`'s options."""

    def __init__(
        self,
        cache: Cache,
        *,
        basis: Literal["haar", "sh", "reference", "ambient"] = "haar",
        brdf: str = "lambert",
        albedo: Optional[Tuple[float, float, float]] = None,
        keep_light: Optional[int] = None,
        keep_visibility: Optional[int] = None,
        depth: Optional[int] = None,
        brdf_rotation: str = "haar",
        level: Optional[int] = None,
        keep_brdf: Optional[int] = None,
        brdf_levels: Optional[int] = None,
        rotation_cache: Optional[int] = None,
        elevations: int = ...,
        fill_cache: bool = False,
        light_rotation: Literal["source", "prefiltered"] = "source",
    ) -> None: ...
    def shade(
        self,
        env: Union[str, "os.PathLike[str]", npt.ArrayLike, None] = None,
        *,
        yaw: Optional[float] = None,
        pitch: Optional[float] = None,
        roll: Optional[float] = None,
        eye: Optional[Tuple[float, float, float]] = None,
    ) -> Tuple[np.ndarray, Dict[str, Union[float, str]]]:
        """Every vertex's outgoing radiance (V, 3) and the timing report."""
