# Type stubs of voxfield.mesh (implemented by the extension module, voxfield._voxfield.mesh).
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

__all__ = ["Terrain", "mesh_volume"]

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
        clamp: float = 0.0,
        chunk: int = 16,
        positive_inside: bool = False,
        palette: npt.ArrayLike | None = None,
    ) -> None: ...
    @property
    def samples(self) -> tuple[int, int, int]: ...
    @property
    def clamp(self) -> float: ...
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
