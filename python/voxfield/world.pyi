# Type stubs of voxfield.world (World is implemented by the extension, voxfield._voxfield.world).
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

__all__ = ["World", "Field", "LiveField", "LiveMesh", "distance_field", "approximate", "render",
           "mesh"]

class World:
    def __init__(
        self, materials: npt.ArrayLike | None = None, origin: Sequence[int] = ..., chunk: int = 32
    ) -> None: ...
    @staticmethod
    def load(path: str, chunk: int = 32, grid: str | None = None) -> World: ...
    def save(self, path: str) -> None: ...
    @property
    def solid_count(self) -> int: ...
    @property
    def extent(self) -> tuple[tuple[int, int, int], tuple[int, int, int]]: ...
    @property
    def content_bounds(self) -> tuple[tuple[int, int, int], tuple[int, int, int]]: ...
    @property
    def chunk(self) -> int: ...
    @property
    def palette(self) -> npt.NDArray[np.uint8]: ...
    @palette.setter
    def palette(self, value: npt.ArrayLike) -> None: ...
    @property
    def origin_world(self) -> tuple[float, float, float]: ...
    @origin_world.setter
    def origin_world(self, value: Sequence[float]) -> None: ...
    @property
    def voxel_size_world(self) -> tuple[float, float, float]: ...
    @voxel_size_world.setter
    def voxel_size_world(self, value: Sequence[float]) -> None: ...
    @property
    def rotation(self) -> npt.NDArray[np.float64]: ...
    @rotation.setter
    def rotation(self, value: npt.ArrayLike) -> None: ...
    def to_world(self, points_vox: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def to_voxels(self, points_world: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def to_numpy(
        self, box: tuple[Sequence[int], Sequence[int]] | None = None
    ) -> npt.NDArray[np.uint8]: ...
    def fill(self, begin: Sequence[int], end: Sequence[int], material: int) -> None: ...
    def apply(
        self,
        op: str,
        shape: str,
        *,
        center: Sequence[float] | None = None,
        radius: float = 1.0,
        min: Sequence[int] | None = None,
        max: Sequence[int] | None = None,
        a: Sequence[float] | None = None,
        b: Sequence[float] | None = None,
        half_extent: Sequence[float] | None = None,
        rotation_deg: Sequence[float] | None = None,
        material: int = 1,
    ) -> tuple[
        tuple[tuple[int, int, int], tuple[int, int, int]] | None,
        int,
        list[tuple[tuple[int, int, int], tuple[int, int, int]]],
    ]: ...

@dataclass
class Field:
    distances: np.ndarray
    scale: float
    bias: int
    origin: tuple[int, int, int]
    sites: np.ndarray | None = ...
    def decoded(self) -> np.ndarray: ...

def distance_field(
    world: World,
    metric: str = "euclidean",
    signed: bool = False,
    max_distance: float = 0.0,
    storage: str = "f32",
    spacing: Sequence[float] = ...,
    sites: bool = False,
    box: tuple[Sequence[int], Sequence[int]] | None = None,
    threads: int = 0,
) -> Field: ...

def approximate(
    world: World,
    algorithm: str = "jfa",
    metric: str = "euclidean",
    signed: bool = False,
    max_distance: float = 0.0,
    storage: str = "f32",
    spacing: Sequence[float] = ...,
    box: tuple[Sequence[int], Sequence[int]] | None = None,
    focus: tuple[Sequence[int], Sequence[int]] | None = None,
    threads: int = 0,
) -> tuple[Field, dict[str, float]]: ...
def render(
    world: World,
    width: int = 640,
    height: int = 360,
    camera: str = "auto",
    view: str = "shaded",
    shadows: bool = True,
    ambient_occlusion: bool = True,
    fog: float = 0.0,
    metric: str = "manhattan",
    threads: int = 0,
    camera_frame: str = "voxels",
) -> npt.NDArray[np.uint8]: ...
def mesh(
    world: World,
    algorithm: str = "mc",
    iso: float = 0.0,
    metric: str = "euclidean",
    chunk: int = 32,
    threads: int = 0,
) -> tuple[
    npt.NDArray[np.float32], npt.NDArray[np.uint32], npt.NDArray[np.float32], npt.NDArray[np.uint8]
]: ...

class LiveField:
    def __init__(
        self,
        world: World,
        metric: str = "euclidean",
        signed: bool = False,
        max_distance: float = 0.0,
        storage: str = "f32",
        spacing: Sequence[float] = ...,
        sites: bool = False,
        box: tuple[Sequence[int], Sequence[int]] | None = None,
    ) -> None: ...
    def apply(
        self,
        op: str,
        shape: str,
        *,
        center: Sequence[float] | None = None,
        radius: float = 1.0,
        min: Sequence[int] | None = None,
        max: Sequence[int] | None = None,
        a: Sequence[float] | None = None,
        b: Sequence[float] | None = None,
        half_extent: Sequence[float] | None = None,
        rotation_deg: Sequence[float] | None = None,
        material: int = 1,
    ) -> tuple[
        tuple[tuple[int, int, int], tuple[int, int, int]] | None,
        int,
        list[tuple[tuple[int, int, int], tuple[int, int, int]]],
        dict[str, int],
    ]: ...
    def rebuild(self) -> None: ...
    def field(self) -> Field: ...

class LiveMesh:
    def __init__(
        self,
        world: World,
        algorithm: str = "mc",
        iso: float = 0.0,
        metric: str = "euclidean",
        chunk: int = 32,
        box: tuple[Sequence[int], Sequence[int]] | None = None,
    ) -> None: ...
    def apply(
        self,
        op: str,
        shape: str,
        *,
        center: Sequence[float] | None = None,
        radius: float = 1.0,
        min: Sequence[int] | None = None,
        max: Sequence[int] | None = None,
        a: Sequence[float] | None = None,
        b: Sequence[float] | None = None,
        half_extent: Sequence[float] | None = None,
        rotation_deg: Sequence[float] | None = None,
        material: int = 1,
    ) -> tuple[
        tuple[tuple[int, int, int], tuple[int, int, int]] | None,
        int,
        list[tuple[tuple[int, int, int], tuple[int, int, int]]],
        list[tuple[int, int, int]],
    ]: ...
    def rebuild(self) -> None: ...
    def mesh(
        self,
    ) -> tuple[
        npt.NDArray[np.float32], npt.NDArray[np.uint32], npt.NDArray[np.float32], npt.NDArray[np.uint8]
    ]: ...
    def chunk_mesh(
        self, chunk: Sequence[int]
    ) -> tuple[
        npt.NDArray[np.float32], npt.NDArray[np.uint32], npt.NDArray[np.float32], npt.NDArray[np.uint8]
    ]: ...
    @property
    def chunk_count(self) -> tuple[int, int, int]: ...
