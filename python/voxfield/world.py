"""Worlds, their files and their exact distance fields (docs/distance.md, docs/formats.md).

``World(materials=None, origin=(0, 0, 0), chunk=32)`` holds materials (0 = air, 1..255) on a
sparse chunked grid and a 256-colour RGBA ``palette``. Arrays are indexed a[x, y, z], element
[i, j, k] being voxel origin + (i, j, k), as voxfield's .npy files and scipy.ndimage index them.
``World.load(path)`` reads .vox, .npy, .vfw or .vdb; ``save(path)`` writes .vox, .npy, .vfw or .vdb
atomically. ``extent`` is the volume the file declared united with the content; ``to_numpy(box)``
copies a box out (default: the extent); ``fill(begin, end, material)`` edits a box.

``distance_field(world, metric="euclidean", signed=False, max_distance=0.0, storage="f32",
spacing=(1, 1, 1), sites=False, box=None, threads=0)`` computes voxfield's exact field over ``box``
(default: the extent): every voxel's distance to the nearest solid voxel (signed: solid voxels read
-(distance to the nearest air voxel)), clamped to ``max_distance`` when it is > 0, in f32, u16 or
u8 storage (integer storage holds ``bias + floor(d * scale)``), with the nearest site's offset
(int16 (X, Y, Z, 3)) when ``sites``. It returns a ``Field``: ``distances`` (as stored),
``scale``, ``bias``, ``sites`` (or None), ``origin`` and ``decoded()`` (float64 distances). The
GIL is released meanwhile; Ctrl-C raises ``voxfield.Cancelled``.

``render(world, width=640, height=360, camera="auto", view="shaded", shadows=True,
ambient_occlusion=True, fog=0.0, metric="manhattan", threads=0, camera_frame="voxels")`` is a
frame of voxfield's DDA ray marcher as uint8 (height, width, 3) RGB, the same pixels as ``voxfield
render`` writes: ``camera`` "auto", "top" or "eye=x,y,z:target=x,y,z[:up=..][:fov=deg][:ortho=h]",
in voxel coordinates, or in the world's frame with ``camera_frame="world"`` (the world's view,
whatever its voxels' shape; ambient occlusion, shadows, the sun and fog stay in voxel terms);
``view`` "shaded", "distance" (a heat map of the field on a cut), "error" or
"chunks"; ``metric``: the skip field's.

``approximate(world, algorithm="jfa", metric="euclidean", signed=False, max_distance=0.0,
storage="f32", spacing=(1, 1, 1), box=None, focus=None, threads=0)`` runs one of the
dissertation's algorithm family ("exact", "brute", "brute-chunked", "fim", "jfa-seed", "jfa",
"jfa+1", "jfa+2", "hybrid", "lod" with a ``focus`` box) and returns ``(Field, report)``: the report
holds its time, passes, iterations and updates, and its error against the exact field (voxels
compared, wrong, too large — unsafe for a ray marcher — too small, the largest errors each way and
the percentages), as ``voxfield compare`` reports them.

Editing: ``world.apply(op, shape, *, center=None, radius=1.0, min=None, max=None, a=None, b=None,
half_extent=None, rotation_deg=None, material=1)`` places, carves or paints (``op``) a "sphere"
(center, radius), "box" (min, max: inclusive voxel corners), "rotated_box" (center, half_extent,
rotation_deg about x then y then z) or "capsule" (a, b, radius) and returns ``(changed box or None,
voxels changed, per-chunk dirty boxes)``. ``LiveField(world, metric="euclidean", signed=False,
max_distance=0.0, storage="f32", spacing=(1, 1, 1), sites=False, box=None)`` computes the field
once and keeps it equal to a rebuild through edits made with its own ``apply`` (same keywords; it
also returns the update's statistics), recomputing only what each edit can change; ``field()``
returns the ``Field``; ``rebuild()`` catches up with edits made to the world another way. A
LiveField keeps its world alive.

``mesh(world, algorithm="mc", iso=0.0, metric="euclidean", chunk=32, threads=0)`` meshes the
surface through the world's exact signed field (``iso`` with |iso| >= 1: an offset surface of the
metric's balls) and returns ``(vertices, faces, normals, colors)``, colours from the palette.
``LiveMesh(world, algorithm="mc", iso=0.0, metric="euclidean", chunk=32, box=None)`` meshes it
once over ``box`` (default: the extent; voxels outside it are air to the mesh) and keeps it
through edits made with its own ``apply`` (same keywords; it also returns the chunks it
re-meshed), re-meshing only the chunks an edit reaches: ``mesh()`` is then ``mesh(world, ...)``
of the edited world, triangle for triangle; ``chunk_mesh((i, j, k))`` one chunk's own mesh (for a
renderer to re-upload), ``chunk_count`` the chunks per axis, ``rebuild()`` catches up with edits
made another way. A LiveMesh keeps its world alive.
"""

from dataclasses import dataclass
from typing import Dict, Optional, Sequence, Tuple

import numpy as np

from ._voxfield import world as _world
from ._voxfield.world import World, mesh, render

__all__ = ["World", "Field", "LiveField", "LiveMesh", "distance_field", "approximate", "render",
           "mesh"]


@dataclass
class Field:
    """An exact distance field: stored values a[x, y, z] from voxel ``origin``, their encoding, and
    the nearest sites' offsets when asked for."""

    distances: np.ndarray
    scale: float
    bias: int
    origin: Tuple[int, int, int]
    sites: Optional[np.ndarray] = None

    def decoded(self) -> np.ndarray:
        """The distances as float64: (stored - bias) / scale."""
        return (self.distances.astype(np.float64) - self.bias) / self.scale


def distance_field(
    world: World,
    metric: str = "euclidean",
    signed: bool = False,
    max_distance: float = 0.0,
    storage: str = "f32",
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    sites: bool = False,
    box: Optional[Tuple[Sequence[int], Sequence[int]]] = None,
    threads: int = 0,
) -> Field:
    """voxfield's exact distance field of ``world`` (see the module's documentation)."""
    spacing = tuple(float(s) for s in spacing)
    if len(spacing) != 3:
        raise _world_error("spacing takes three numbers (x, y, z)")
    if box is not None:
        box = (tuple(int(v) for v in box[0]), tuple(int(v) for v in box[1]))
    out = _world.distance_field(world, metric, signed, max_distance, storage, spacing, sites, box,
                                threads)
    return Field(distances=out[0], scale=out[1]["scale"], bias=out[1]["bias"],
                 origin=out[1]["origin"], sites=out[2] if sites else None)


def approximate(
    world: World,
    algorithm: str = "jfa",
    metric: str = "euclidean",
    signed: bool = False,
    max_distance: float = 0.0,
    storage: str = "f32",
    spacing: Sequence[float] = (1.0, 1.0, 1.0),
    box: Optional[Tuple[Sequence[int], Sequence[int]]] = None,
    focus: Optional[Tuple[Sequence[int], Sequence[int]]] = None,
    threads: int = 0,
) -> Tuple[Field, Dict[str, float]]:
    """One of the algorithm family's fields and its error against the exact one (see above)."""
    spacing = tuple(float(s) for s in spacing)
    box = None if box is None else (tuple(int(v) for v in box[0]), tuple(int(v) for v in box[1]))
    if focus is not None:
        focus = (tuple(int(v) for v in focus[0]), tuple(int(v) for v in focus[1]))
    out, report = _world.approximate(world, algorithm, metric, signed, max_distance, storage,
                                     spacing, box, focus, threads)
    return Field(distances=out[0], scale=out[1]["scale"], bias=out[1]["bias"],
                 origin=out[1]["origin"]), report


class LiveField(_world.LiveField):
    """An exact distance field of a World kept equal to a rebuild through its ``apply`` edits."""

    def field(self) -> Field:
        """The field as it stands: stored distances over the LiveField's box, and sites if kept."""
        out = self._field()
        return Field(distances=out[0], scale=out[1]["scale"], bias=out[1]["bias"],
                     origin=out[1]["origin"], sites=out[2] if len(out) > 2 else None)

    def __init__(self, world: World, metric: str = "euclidean", signed: bool = False,
                 max_distance: float = 0.0, storage: str = "f32",
                 spacing: Sequence[float] = (1.0, 1.0, 1.0), sites: bool = False,
                 box: Optional[Tuple[Sequence[int], Sequence[int]]] = None) -> None:
        spacing = tuple(float(s) for s in spacing)
        if box is not None:
            box = (tuple(int(v) for v in box[0]), tuple(int(v) for v in box[1]))
        super().__init__(world, metric, signed, max_distance, storage, spacing, sites, box)


class LiveMesh(_world.LiveMesh):
    """A World's surface kept per chunk through its ``apply`` edits (see above)."""

    def __init__(self, world: World, algorithm: str = "mc", iso: float = 0.0,
                 metric: str = "euclidean", chunk: int = 32,
                 box: Optional[Tuple[Sequence[int], Sequence[int]]] = None) -> None:
        if box is not None:
            box = (tuple(int(v) for v in box[0]), tuple(int(v) for v in box[1]))
        super().__init__(world, algorithm, float(iso), metric, int(chunk), box)


def _world_error(message: str) -> Exception:
    from ._voxfield import InvalidArgument

    return InvalidArgument(message)
