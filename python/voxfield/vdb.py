"""OpenVDB files (.vdb) read by voxfield's own parser (docs/formats.md), safe on damaged files.

``read(path, memory_limit=0)`` returns the file's grids in its order: Float, Double, Bool, Int32
and Vec3f grids of any node configuration, stored uncompressed, zip or Blosc, in full or half
precision (other grid types are skipped). Each ``Grid`` has its ``name``, ``value_type``
('float', 'double', 'bool', 'int32', 'vec3s'), ``grid_class`` ('level set', 'fog volume'...),
``index_to_world`` ((3, 4): world = m @ (i, j, k, 1)), ``voxel_size``, ``background``,
``metadata`` (a dict), ``active_bounds`` and ``stored_bounds`` (((x0, y0, z0), (x1, y1, z1)), end
exclusive, in index space), and ``to_numpy(box=None)`` / ``active_mask(box=None)``: the values and
the activity over a box (default: the active bounds) as a[x, y, z] (a[x, y, z, 3] for vec3s),
element [i, j, k] being voxel box[0] + (i, j, k), as pyopenvdb's ``copyToArray`` fills them.

A damaged file raises ``voxfield.FormatError`` (a ValueError) naming the file and the byte offset,
where OpenVDB's own reader may abort the process; a file whose trees would pass the memory limit
raises ``voxfield.ResourceLimitError``. ``voxfield.world.World.load`` reads the world a .vdb holds.
"""

from ._voxfield.vdb import Grid, read

__all__ = ["Grid", "read"]
