# Type stubs of voxfield.ndimage: SciPy's distance-transform signatures, plus signed, max_distance
# and threads (keyword-only).
from collections.abc import Sequence
from typing import Any, Literal

import numpy as np
import numpy.typing as npt

__all__ = ["distance_transform_edt", "distance_transform_cdt"]

def distance_transform_edt(
    input: npt.ArrayLike,
    sampling: float | Sequence[float] | None = None,
    return_distances: bool = True,
    return_indices: bool = False,
    distances: npt.NDArray[np.float64] | None = None,
    indices: npt.NDArray[np.int32] | None = None,
    *,
    signed: bool = False,
    max_distance: float = 0,
    threads: int | None = None,
) -> Any: ...
def distance_transform_cdt(
    input: npt.ArrayLike,
    metric: Literal["chessboard", "taxicab", "cityblock", "manhattan"] = "chessboard",
    return_distances: bool = True,
    return_indices: bool = False,
    distances: npt.NDArray[np.int32] | None = None,
    indices: npt.NDArray[np.int32] | None = None,
    *,
    signed: bool = False,
    max_distance: float = 0,
    threads: int | None = None,
) -> Any: ...
