# Type stubs of voxfield.mesh (implemented by the extension module, voxfield._voxfield.mesh).
import os
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

__all__ = ["Terrain", "WindingNumber", "mesh_distance_field", "mesh_volume", "read_mesh", "voxelize_mesh"]

def mesh_volume(
    volume: npt.ArrayLike,
    level: float = 0.0,
    spacing: Sequence[float] = ...,
    inside: str = "below",
    algorithm: str = "mc",
    chunk: int = 32,
    threads: int = 0,
) -> tuple[npt.NDArray[np.float32], npt.NDArray[np.uint32], npt.NDArray[np.float32]]: ...

class Terrain:
    def __init__(
        self,
        samples: Sequence[int],
        storage: str = "i16",
        spacing: float = 1.0,
        origin: Sequence[float] = ...,
        max_distance: float = 0.0,
        chunk: int = 16,
        positive_inside: bool = False,
        palette: npt.ArrayLike | None = None,
    ) -> None: ...
    @property
    def samples(self) -> tuple[int, int, int]: ...
    @property
    def max_distance(self) -> float: ...
    @property
    def step(self) -> float: ...
    @property
    def memory(self) -> dict[str, int]: ...
    def assign(self, values: npt.ArrayLike, material: int = 0) -> None: ...
    def apply(
        self,
        shape: str,
        mode: str = "add",
        *,
        centre: Sequence[float],
        radius: float = 1.0,
        end: Sequence[float] | None = None,
        half_extents: Sequence[float] | None = None,
        smooth: float = 0.0,
        material: int = 1,
    ) -> tuple[tuple[int, int, int], tuple[int, int, int]] | None: ...
    def values(self) -> npt.NDArray[np.float32]: ...
    def materials(self) -> npt.NDArray[np.uint8]: ...
    def mesh(
        self, algorithm: str = "mc", chunk: int = 32
    ) -> tuple[
        npt.NDArray[np.float32], npt.NDArray[np.uint32], npt.NDArray[np.float32], npt.NDArray[np.uint8]
    ]: ...

def read_mesh(path: str | os.PathLike[str]) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]: ...

class WindingNumber:
    def __init__(self, vertices: npt.ArrayLike, faces: npt.ArrayLike, accuracy: float = 2.0) -> None: ...
    def __call__(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def exact(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def inside(self, points: npt.ArrayLike) -> npt.NDArray[np.bool_]: ...

def voxelize_mesh(
    vertices: npt.ArrayLike,
    faces: npt.ArrayLike,
    voxel_size: float,
    padding: int = 2,
    material: int = 1,
    accuracy: float = 2.0,
    threads: int = 0,
) -> tuple[npt.NDArray[np.uint8], tuple[int, int, int]]: ...

def mesh_distance_field(
    vertices: npt.ArrayLike,
    faces: npt.ArrayLike,
    voxel_size: float,
    padding: int = 2,
    band: float = 3.0,
    signed: bool = True,
    max_distance: float = 0.0,
    accuracy: float = 2.0,
    threads: int = 0,
) -> tuple[npt.NDArray[np.float32], tuple[int, int, int]]: ...
