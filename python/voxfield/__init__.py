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

__all__ = ["ndimage", "csg", "mesh", "vectors", "vdb", "world", "Error", "InvalidArgument", "FormatError", "ResourceLimitError", "IoError",
           "Cancelled"]
