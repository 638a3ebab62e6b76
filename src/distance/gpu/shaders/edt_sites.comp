// voxfield — first pass of the separable exact distance transform (Meijster, Roerdink & Hesselink,
// "A general algorithm for computing distance transforms in linear time", 2000): along each line
// of the compute box (axis p.axis: z, as on the CPU, so nearest-site ties break the same way), the
// distance to the nearest site on that line, by one sweep each way; a tie goes to the site before
// (the smaller coordinate). Sites are the solid voxels, or the air voxels for the inside half of a
// signed field. One invocation per line; neighbouring invocations walk neighbouring lines, so
// their reads are contiguous. Writes cost p.dst: the distance (L1, L-infinity) or its square (L2),
// VF_INF when the line holds no site — and, with nearest sites, the site itself. A slab of a larger
// domain (p.column_neighbours) starts each column's sweeps from the nearest sites beyond its z
// faces, so that its values equal the whole domain's (include/voxfield/distance_slab.h).
#version 450
#include "common.glsl"

void main() {
  const uint line = invocation();
  const ivec3 n = p.box_size.xyz;
  const int len = n[p.axis];
  if (line >= uint(n.x * n.y * n.z / len)) return;
  ivec3 first, step;
  line_of(line, first, step);
  const ivec3 origin = p.box_begin.xyz;
  const bool sites = h.track_sites != 0u;
  // The nearest sites before and after the line, as offsets along it (a slab's neighbours, when
  // this box reaches the slab's face on that side; otherwise none).
  bool found = false, have_next = false;
  int last = 0, next = 0;
  if (p.column_neighbours != 0u && p.axis == 2u) {
    const ivec2 c = origin.xy + first.xy - p.table.xy;
    const int word =
        int(neighbour_words[uint(p.table.w) + 2u * uint(c.y * p.table.z + c.x) + p.sites_are_air]);
    const int below = bitfieldExtract(word, 0, 16), above = bitfieldExtract(word, 16, 16);
    // (Offsets count from the slab's first slice; u from the box's.)
    if (below != VF_NO_NEIGHBOUR && origin.z == p.faces.x) {
      found = true;
      last = below + p.faces.x - origin.z;
    }
    if (above != VF_NO_NEIGHBOUR && origin.z + len == p.faces.y) {
      have_next = true;
      next = above + p.faces.x - origin.z;
    }
  }
  // Forward: distance to the nearest site at or before u.
  for (int u = 0; u < len; ++u) {
    const ivec3 l = first + step * u;
    const bool solid = material_at(origin + l) != 0u;
    if (solid != (p.sites_are_air != 0u)) {
      found = true;
      last = u;
    }
    const uint i = voxel_index(l);
    store_cost(p.dst, i, found ? uint(u - last) : VF_INF);
    if (sites) store_site(p.dst, i, found ? pack_site(first + step * last) : uvec2(VF_INF, 0u));
  }
  // Backward: the nearest site after u, if strictly closer; then square for L2.
  for (int u = len - 1; u >= 0; --u) {
    const ivec3 l = first + step * u;
    const uint i = voxel_index(l);
    uint d = load_cost(p.dst, i);
    if (d == 0u) {
      have_next = true;
      next = u;
    }
    if (have_next && uint(next - u) < d) {
      d = uint(next - u);
      if (sites) store_site(p.dst, i, pack_site(first + step * next));
    }
    if (d != VF_INF && h.metric == VF_EUCLIDEAN) d = d * d;
    store_cost(p.dst, i, d);
  }
}
