"""voxfield: exact distance fields of voxel worlds and volumes, from Python.

``voxfield.csg`` compiles CSG models (docs/csg.md): ``Model(text)`` or ``Model.load(path)``
(.sdf, .json, OpenSCAD .csg), then ``evaluate(points)``, ``voxelize(voxel_size)``, ``mesh(...)``.

``voxfield.mesh`` meshes NumPy volumes (``mesh_volume``: marching cubes, surface nets, dual
contouring) and keeps a deformable ``Terrain`` field edited by brushes (docs/meshing.md).

``voxfield.vectors`` renders moving sources into vector-field volume textures (docs/vectors.md):
``Volume``, ``generate``, ``exact`` and ``Simulation`` (steps with decay and blend, sampling, the
visualiser's picture).

``voxfield.vdb`` reads OpenVDB files with voxfield's own parser, safe on damaged files: each
grid's values and activity over a box as NumPy arrays, its transform and metadata.

``voxfield.world`` holds worlds (``World``: NumPy arrays in and out, .vox/.npy/.vfw/.vdb read and
written) and computes their exact distance fields (``distance_field``: every metric, sign,
clamp, storage and spacing, nearest sites).

``voxfield.ndimage`` is a drop-in for ``scipy.ndimage.distance_transform_edt`` and
``distance_transform_cdt`` (same arguments, results, shapes, dtypes and index layout), computed
by voxfield's exact separable transforms on every core, with what SciPy lacks: ``signed``,
``max_distance`` and ``threads``.

Memory: voxfield keeps the voxel arrays of grids and fields it frees for the next call (a second
transform of the same size takes its chunk arrays from them rather than from fresh pages), up to ``chunk_cache_limit()`` bytes — a
sixteenth of physical memory, at most 1 GiB, unless the environment variable
``VOXFIELD_CHUNK_CACHE`` says otherwise ("512M"; "0" turns it off). ``set_chunk_cache_limit``,
``trim_chunk_cache`` and ``chunk_memory_stats`` manage it.

voxfield's errors are Python exceptions: ``InvalidArgument`` and ``FormatError`` (ValueError),
``ResourceLimitError`` (MemoryError), ``IoError`` (OSError), ``Cancelled`` (KeyboardInterrupt);
their messages name the file and, for malformed files, the byte offset.
"""

from . import _voxfield
from ._voxfield import Cancelled, Error, FormatError, InvalidArgument, IoError, ResourceLimitError
from . import ndimage
from . import csg
from . import mesh
from . import vectors
from . import vdb
from . import world


def chunk_cache_limit():
    """Bytes of freed voxel arrays voxfield keeps for reuse (0: none kept)."""
    return _voxfield.chunk_cache_limit()


def set_chunk_cache_limit(nbytes):
    """Sets the limit in bytes (0 disables the cache) and hands back what exceeds it."""
    nbytes = int(nbytes)
    if nbytes < 0:
        raise ValueError(f"set_chunk_cache_limit: {nbytes} bytes is negative")
    _voxfield.set_chunk_cache_limit(nbytes)


def trim_chunk_cache():
    """Hands every cached voxel array back to the system; the limit stays."""
    _voxfield.trim_chunk_cache()


def chunk_memory_stats():
    """{'cached_bytes', 'limit_bytes', 'reused', 'allocated'}: the cache now, and since start."""
    return dict(_voxfield.chunk_memory_stats())


__all__ = ["ndimage", "csg", "mesh", "vectors", "vdb", "world", "Error", "InvalidArgument", "FormatError", "ResourceLimitError", "IoError",
           "Cancelled", "chunk_cache_limit", "set_chunk_cache_limit", "trim_chunk_cache", "chunk_memory_stats"]
