"""CSG models compiled by voxfield's voxel compiler (docs/csg.md).

``Model(text, name)`` parses the model language (S-expressions, or JSON when the text starts with
'['); ``Model.load(path, facets=False)`` reads .sdf, .json or OpenSCAD's .csg. A model then gives:

- ``evaluate(points)``: its value at a float64 (N, 3) array of points, float64 (N,);
- ``materials(points)``: the paint at each point, uint8 (N,);
- ``voxelize(voxel_size, box=None, max_distance=None, field=False)``: uint8 materials a[i, j, k]
  (i along x, Fortran order, as voxfield's .npy files), and with ``field=True`` the float32 values
  at the voxel centres too;
- ``octree(depth)``: the figures of its octree of pruned tapes (variants, nodes per cell...);
- ``mesh(voxel_size, algorithm="dc")``: (vertices, faces, normals, colors) with crossings and
  normals from the model itself;
- ``nodes``, ``shapes``, ``label``, ``bounds``, ``palette``.

Malformed models raise ``ModelError`` (a ValueError) naming the line and column.
"""

from ._voxfield.csg import Model, ModelError, translate_openscad

__all__ = ["Model", "ModelError", "translate_openscad"]
