# Type stubs of voxfield.vectors (implemented by the extension module, voxfield._voxfield.vectors).
from collections.abc import Sequence

import numpy as np
import numpy.typing as npt

__all__ = ["Simulation", "Volume", "exact", "generate"]

class Volume:
    def __init__(
        self,
        centre: Sequence[float] = ...,
        size: Sequence[float] = ...,
        resolution: Sequence[int] = ...,
        rotation_degrees: float = 0.0,
        rotation_axis: Sequence[float] = ...,
    ) -> None: ...
    @property
    def resolution(self) -> tuple[int, int, int]: ...
    def voxel_centre(self, i: int, j: int, k: int) -> tuple[float, float, float]: ...

def generate(
    volume: Volume,
    sources: npt.ArrayLike,
    algorithm: str = "splat",
    rule: str = "strongest",
    storage: str = "rgba32f",
) -> npt.NDArray[np.float32]: ...
def exact(
    points: npt.ArrayLike, sources: npt.ArrayLike, rule: str = "strongest"
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]: ...

class Simulation:
    def __init__(
        self,
        volume: Volume,
        storage: str = "rgba8",
        algorithm: str = "splat",
        rule: str = "strongest",
        decay_per_s: float = 1.0,
    ) -> None: ...
    def step(self, sources: npt.ArrayLike, dt: float) -> None: ...
    def field(self) -> npt.NDArray[np.float32]: ...
    def current(self) -> npt.NDArray[np.float32]: ...
    def sample(self, points: npt.ArrayLike) -> npt.NDArray[np.float64]: ...
    def render(
        self, width: int = 640, height: int = 480, eye: Sequence[float] | None = None, sheet: bool = False
    ) -> npt.NDArray[np.uint8]: ...
    @property
    def steps(self) -> int: ...
    @property
    def last_times(self) -> dict[str, float]: ...
