"""Distance transforms with SciPy's interface, on voxfield's exact transforms.

``distance_transform_edt`` and ``distance_transform_cdt`` take the arguments of
``scipy.ndimage``'s functions of the same names and return the same things: the distance of every
non-zero element of ``input`` to the nearest zero element (float64 for the Euclidean transform,
int32 for taxicab and chessboard), and with ``return_indices`` the index of that zero element
(int32, shape ``(input.ndim,) + input.shape``); ``distances=`` and ``indices=`` are filled in place
(and then not returned), and the same RuntimeErrors are raised for inconsistent arguments. Inputs
of 1 to 3 dimensions, of any dtype and memory order, are read where they lie (no copy for booleans,
integers and floats).

What SciPy lacks:

* ``signed=True``: zero elements read minus their distance to the nearest non-zero element (their
  index is then that element's);
* ``max_distance=D``: distances are clamped at D (an element with no zero within D reads D and,
  with indices, -1), which bounds the work on large volumes;
* ``threads=N``: at most N threads (default: every core); the GIL is released meanwhile.

Where the input holds no zero element at all, the Euclidean distances are +inf and the indices -1
(SciPy returns values measured from a phantom element outside the array there); the integer
transforms read -1, as SciPy's.

Ties: where two zero elements are equally near, the distance is the same as SciPy's; the index may
name the other one (voxfield's tie rule is in docs/distance.md).
"""

import numbers

import numpy as np

from . import _voxfield

__all__ = ["distance_transform_edt", "distance_transform_cdt"]


def _arg_check(dt_inplace, ft_inplace, return_distances, return_indices):
    # The same checks and messages as scipy.ndimage.
    errors = []
    if not return_distances and not return_indices:
        errors.append("at least one of return_distances/return_indices must be True")
    if dt_inplace and not return_distances:
        errors.append("return_distances must be True if distances is supplied")
    if ft_inplace and not return_indices:
        errors.append("return_indices must be True if indices is supplied")
    if errors:
        raise RuntimeError(", ".join(errors))


def _as_input(input):
    a = np.asarray(input)
    if a.ndim == 0:
        a = a.reshape(1)
    if a.ndim > 3:
        raise ValueError(f"voxfield.ndimage: inputs of 1 to 3 dimensions (got {a.ndim})")
    if a.dtype.kind not in "biuf" or (a.dtype.kind == "f" and a.dtype.itemsize not in (4, 8)):
        a = a != 0  # complex, float16, objects: their truth value, as SciPy takes it
    return a


def _check_common(max_distance, threads):
    if not isinstance(max_distance, numbers.Real) or not np.isfinite(max_distance) or max_distance < 0:
        raise ValueError("max_distance must be a finite number >= 0 (0: no clamp)")
    if threads is None:
        return 0
    if not isinstance(threads, numbers.Integral) or not 1 <= threads <= 1024:
        raise ValueError("threads must be an integer from 1 to 1024 (or None: every core)")
    return int(threads)


def _run(a, metric, sampling, signed, max_distance, threads, dt, ft):
    # The engine writes native-endian values to aligned memory: byte-swapped or misaligned
    # outputs get them through a copy.
    outs = [dt, ft]
    tmp = [o if o is None or (o.dtype.isnative and o.flags.aligned)
           else np.empty(o.shape, o.dtype.newbyteorder("=")) for o in outs]
    _voxfield._distance_transform(a, metric, sampling, bool(signed), float(max_distance), threads,
                                  tmp[0], tmp[1])
    for o, t in zip(outs, tmp):
        if o is not None and t is not o:
            o[...] = t


def _result(return_distances, dt_inplace, dt, return_indices, ft_inplace, ft):
    result = []
    if return_distances and not dt_inplace:
        result.append(dt)
    if return_indices and not ft_inplace:
        result.append(ft)
    if len(result) == 2:
        return tuple(result)
    if len(result) == 1:
        return result[0]
    return None


def distance_transform_edt(input, sampling=None, return_distances=True, return_indices=False,
                           distances=None, indices=None, *, signed=False, max_distance=0,
                           threads=None):
    """Exact Euclidean distance transform, as ``scipy.ndimage.distance_transform_edt``.

    ``sampling``: the spacing of the elements along each axis (a number or one per axis), in the
    units the distances are given in. ``signed``, ``max_distance`` (in those units) and ``threads``:
    see the module's documentation.
    """
    ft_inplace = isinstance(indices, np.ndarray)
    dt_inplace = isinstance(distances, np.ndarray)
    _arg_check(dt_inplace, ft_inplace, return_distances, return_indices)
    a = _as_input(input)
    n_threads = _check_common(max_distance, threads)
    if sampling is not None:
        sampling = np.broadcast_to(np.asarray(sampling, dtype=np.float64).ravel(), (a.ndim,)) \
            if np.ndim(sampling) == 0 else np.asarray(sampling, dtype=np.float64)
        if sampling.shape != (a.ndim,):
            raise RuntimeError("sequence argument must have length equal to input rank")
        if not np.all(np.isfinite(sampling)) or np.any(sampling <= 0):
            raise ValueError("sampling must be finite and > 0 along every axis")
        sampling = [float(s) for s in sampling]
    if ft_inplace:
        if indices.shape != (a.ndim,) + a.shape:
            raise RuntimeError("indices array has wrong shape")
        if indices.dtype.type != np.int32:
            raise RuntimeError("indices array must be int32")
        ft = indices
    else:
        ft = np.empty((a.ndim,) + a.shape, dtype=np.int32) if return_indices else None
    if dt_inplace:
        if distances.shape != a.shape:
            raise RuntimeError("distances array has wrong shape")
        if distances.dtype.type != np.float64:
            raise RuntimeError("distances array must be float64")
        dt = distances
    else:
        dt = np.empty(a.shape, dtype=np.float64) if return_distances else None
    _run(a, "euclidean", sampling, signed, max_distance, n_threads, dt, ft)
    return _result(return_distances, dt_inplace, dt, return_indices, ft_inplace, ft)


def distance_transform_cdt(input, metric="chessboard", return_distances=True,
                           return_indices=False, distances=None, indices=None, *, signed=False,
                           max_distance=0, threads=None):
    """Exact taxicab or chessboard distance transform, as ``scipy.ndimage.distance_transform_cdt``.

    ``metric``: ``'chessboard'`` (default), or ``'taxicab'`` (also ``'cityblock'``,
    ``'manhattan'``). SciPy's arbitrary 3^n structuring elements are not supported (ValueError):
    voxfield computes the two exact metrics, not chamfer approximations.
    """
    ft_inplace = isinstance(indices, np.ndarray)
    dt_inplace = isinstance(distances, np.ndarray)
    _arg_check(dt_inplace, ft_inplace, return_distances, return_indices)
    if isinstance(metric, str) and metric in ("taxicab", "cityblock", "manhattan"):
        name = "taxicab"
    elif isinstance(metric, str) and metric == "chessboard":
        name = "chessboard"
    else:
        raise ValueError("voxfield.ndimage.distance_transform_cdt: metric must be 'chessboard' "
                         "or 'taxicab' ('cityblock', 'manhattan'); structuring elements are not "
                         "supported")
    a = _as_input(input)
    n_threads = _check_common(max_distance, threads)
    if dt_inplace:
        if distances.dtype.type != np.int32:
            raise RuntimeError("distances must be of int32 type")
        if distances.shape != a.shape:
            raise RuntimeError("distances has wrong shape")
        dt = distances
    else:
        dt = np.empty(a.shape, dtype=np.int32) if return_distances else None
    if ft_inplace:
        if indices.dtype.type != np.int32:
            raise RuntimeError("indices array must be int32")
        if indices.shape != (a.ndim,) + a.shape:
            raise RuntimeError("indices array has wrong shape")
        ft = indices
    else:
        ft = np.empty((a.ndim,) + a.shape, dtype=np.int32) if return_indices else None
    _run(a, name, None, signed, max_distance, n_threads, dt, ft)
    return _result(return_distances, dt_inplace, dt, return_indices, ft_inplace, ft)
