// voxfield — first pass of the separable exact distance transform (Meijster, Roerdink & Hesselink,
// "A general algorithm for computing distance transforms in linear time", 2000): along each line
// of the compute box (axis p.axis: z, as on the CPU, so nearest-site ties break the same way), the
// distance to the nearest site on that line, by one sweep each way; a tie goes to the site before
// (the smaller coordinate). Sites are the solid voxels, or the air voxels for the inside half of a
// signed field. One invocation per line; neighbouring invocations walk neighbouring lines, so
// their reads are contiguous. Writes cost p.dst: the distance (L1, L-infinity) or its square (L2),
// VF_INF when the line holds no site — and, with nearest sites, the site itself.
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
  // Forward: distance to the nearest site at or before u.
  int last = -1;
  for (int u = 0; u < len; ++u) {
    const ivec3 l = first + step * u;
    const bool solid = material_at(origin + l) != 0u;
    if (solid != (p.sites_are_air != 0u)) last = u;
    const uint i = voxel_index(l);
    store_cost(p.dst, i, last < 0 ? VF_INF : uint(u - last));
    if (sites) store_site(p.dst, i, last < 0 ? uvec2(VF_INF, 0u) : pack_site(first + step * last));
  }
  // Backward: the nearest site after u, if strictly closer; then square for L2.
  int next = -1;
  for (int u = len - 1; u >= 0; --u) {
    const ivec3 l = first + step * u;
    const uint i = voxel_index(l);
    uint d = load_cost(p.dst, i);
    if (d == 0u) next = u;
    if (next >= 0 && uint(next - u) < d) {
      d = uint(next - u);
      if (sites) store_site(p.dst, i, pack_site(first + step * next));
    }
    if (d != VF_INF && h.metric == VF_EUCLIDEAN) d = d * d;
    store_cost(p.dst, i, d);
  }
}
