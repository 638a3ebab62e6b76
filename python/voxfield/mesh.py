"""Meshes of volumes and deformable terrain (docs/meshing.md).

``mesh_volume(volume, level=0.0, spacing=(1, 1, 1), inside="below", algorithm="mc", chunk=32,
threads=0)`` meshes the iso-surface of a 3-D array a[i, j, k] (i along x, as scikit-image indexes
it: vertex (x, y, z) = (i, j, k) * spacing) and returns ``(vertices, faces, normals)``: float32
(V, 3), uint32 (F, 3) counter-clockwise seen from outside, float32 (V, 3) unit normals pointing
out. ``inside="below"`` suits signed distance fields, ``"above"`` densities (scikit-image's
default, 'descent'). ``algorithm``: ``"mc"`` (marching cubes: a closed oriented 2-manifold),
``"sn"`` (surface nets) or ``"dc"`` (dual contouring). The triangles do not depend on ``chunk``
(only the order vertices are numbered in does) or on ``threads`` (not even the order). A float32 Fortran-ordered array is read in place; others are converted once.

``Terrain(samples, storage="i16", spacing=1.0, origin=(0, 0, 0), max_distance=0.0, chunk=16,
positive_inside=False, palette=None)`` is voxfield's terrain field: signed distances stored per
chunk in i8, i16 or f32, clamped to ±max_distance, uniform chunks stored once. ``assign(values,
material)`` fills it from an array; ``apply(shape, mode, centre, radius, end, half_extents,
smooth, material)`` adds or subtracts a sphere, box or capsule (sharp, or blended by a polynomial
smooth minimum over ``smooth`` units) and returns the box of samples it changed; ``values()`` and
``materials()`` read it back; ``mesh(algorithm, chunk)`` returns ``(vertices, faces, normals,
colors)`` with colours from the palette by material.

Meshes in (docs/mesh_input.md): ``read_mesh(path)`` reads an OBJ, PLY, STL or OFF file as
``(vertices float64 (V, 3), faces uint32 (F, 3))``. ``WindingNumber(vertices, faces,
accuracy=2.0)`` is the mesh's generalized winding number (1 inside, 0 outside, in between near a
hole): call it on points (N, 3), or ``exact(points)``, or ``inside(points)`` (>= 1/2).
``voxelize_mesh(vertices, faces, voxel_size, padding=2, material=1)`` returns ``(materials,
first)``: uint8 a[i, j, k] solid where the winding number at the voxel's centre is >= 1/2, over
the mesh's bounds grown by ``padding`` voxels, a[i, j, k] being voxel ``first + (i, j, k)``
centred at ``(first + (i, j, k) + 1/2) * voxel_size``. ``mesh_distance_field(vertices, faces,
voxel_size, padding=2, band=3.0, signed=True, max_distance=0.0)`` returns ``(values, first)``:
float32 distances to the mesh at the same voxel centres, in the mesh's units, exact within
``band`` voxels of the surface, negative inside.

Errors are voxfield's: a bad argument or a NaN sample raises ``voxfield.InvalidArgument`` (a
ValueError) naming it, a malformed mesh file ``voxfield.FormatError`` naming the file and the byte
offset; Ctrl-C stops a long mesh, voxelisation or field with ``voxfield.Cancelled``.
"""

from ._voxfield.mesh import Terrain, WindingNumber, mesh_distance_field, mesh_volume, read_mesh, voxelize_mesh

__all__ = ["Terrain", "WindingNumber", "mesh_distance_field", "mesh_volume", "read_mesh", "voxelize_mesh"]
