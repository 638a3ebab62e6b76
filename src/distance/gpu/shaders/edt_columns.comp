// voxfield — the column neighbours of the z-slabs a region of the exact transform is cut into when
// its box is too large for the work buffers. Meijster, Roerdink & Hesselink ("A general algorithm
// for computing distance transforms in linear time", 2000) run their first pass along z and their
// other passes within slices, so a slab needs from the rest of its columns only the nearest site
// below it and the nearest above it (include/voxfield/distance_slab.h): given those, edt_sites
// starts each column's sweeps from them and the slab's values are the whole box's.
//
// One invocation per column of the box (p.box_begin, p.box_size), walking it up, then down: for
// each slab k of p.faces.z slices (p.faces.w of them, the last maybe thinner) it writes at word
// p.table.w + 2 * (k * columns + column) + kind — kind 0 the solid voxels, 1 the air — the nearest
// below the slab and above it, as int16 offsets from the slab's first slice (VF_NO_NEIGHBOUR for
// none). Beyond the box's own z faces lie the sites the field's table at word 0 names when the box
// reaches the field's faces and p.column_neighbours is set (the field is itself a slab of a larger
// domain: an MPI rank's), and nothing otherwise.
#version 450
#define VF_NEIGHBOURS_ACCESS
#include "common.glsl"

const int kNone = -2147483647;  // no such voxel (a z no slab is near)

// The nearest voxel of `kind` beyond the field's faces for the box's column at `xy`, as an
// absolute z: below (side 0) or above (side 1); kNone when none or when the box does not reach
// that face of the field.
int beyond_field(ivec2 xy, uint kind, int side) {
  if (p.column_neighbours == 0u) return kNone;
  const int face = side == 0 ? h.field_begin.z : h.field_begin.z + h.field_size.z;
  const int box_face = side == 0 ? p.box_begin.z : p.box_begin.z + p.box_size.z;
  if (face != box_face) return kNone;
  const ivec2 c = xy - h.field_begin.xy;
  const int word = int(neighbour_words[2u * uint(c.y * h.field_size.x + c.x) + kind]);
  const int offset = bitfieldExtract(word, side * 16, 16);
  return offset == VF_NO_NEIGHBOUR ? kNone : h.field_begin.z + offset;
}

// An absolute z as an offset from slab first slice `z0`, packed into the low 16 bits.
uint packed_offset(int z, int z0) {
  return uint(z == kNone ? VF_NO_NEIGHBOUR : z - z0) & 0xFFFFu;
}

void main() {
  const uint column = invocation();
  const ivec3 n = p.box_size.xyz;
  const uint columns = uint(n.x * n.y);
  if (column >= columns) return;
  const ivec2 xy = p.box_begin.xy + ivec2(int(column) % n.x, int(column) / n.x);
  const int z0 = p.box_begin.z, z1 = z0 + n.z, thickness = p.faces.z;
  const uint base = uint(p.table.w);
  // Up: at each slab's first slice, the nearest of each kind below it; the above halves wait.
  int below[2] = int[2](beyond_field(xy, 0u, 0), beyond_field(xy, 1u, 0));
  for (int z = z0; z < z1; ++z) {
    if ((z - z0) % thickness == 0) {
      const uint at = base + 2u * (uint((z - z0) / thickness) * columns + column);
      for (uint kind = 0u; kind < 2u; ++kind)
        neighbour_words[at + kind] = packed_offset(below[kind], z);
    }
    below[material_at(ivec3(xy, z)) != 0u ? 0 : 1] = z;
  }
  // Down: at each slab's last slice, the nearest of each kind above it.
  int above[2] = int[2](beyond_field(xy, 0u, 1), beyond_field(xy, 1u, 1));
  for (int z = z1 - 1; z >= z0; --z) {
    if (z == z1 - 1 || (z + 1 - z0) % thickness == 0) {
      const int slab = (z - z0) / thickness;
      const uint at = base + 2u * (uint(slab) * columns + column);
      const int first = z0 + slab * thickness;
      for (uint kind = 0u; kind < 2u; ++kind)
        neighbour_words[at + kind] =
            (neighbour_words[at + kind] & 0xFFFFu) | (packed_offset(above[kind], first) << 16);
    }
    above[material_at(ivec3(xy, z)) != 0u ? 0 : 1] = z;
  }
}
