// voxfield — first pass of the separable exact distance transform (Meijster, Roerdink & Hesselink,
// "A general algorithm for computing distance transforms in linear time", 2000): along each row
// of the compute box (x), the distance to the nearest site in that row, by one sweep each way. Sites
// are the solid voxels, or the air voxels for the inside half of a signed field. One invocation
// per row. Writes cost p.dst: the distance (L1, L-infinity) or its square (L2), VF_INF when the row
// holds no site.
#version 450
#include "common.glsl"

void main() {
  const uint row = invocation();
  const ivec3 n = p.box_size.xyz;
  if (row >= uint(n.y * n.z)) return;
  ivec3 first, step;
  line_of(row, first, step);
  const int len = n.x;
  const ivec3 origin = p.box_begin.xyz;
  // Forward: distance to the nearest site at or before x.
  int last = -1;
  for (int x = 0; x < len; ++x) {
    const ivec3 l = first + step * x;
    const bool solid = material_at(origin + l) != 0u;
    if (solid != (p.sites_are_air != 0u)) last = x;
    store_cost(p.dst, voxel_index(l), last < 0 ? VF_INF : uint(x - last));
  }
  // Backward: the nearest site after x, if closer; then square for L2.
  int next = -1;
  for (int x = len - 1; x >= 0; --x) {
    const ivec3 l = first + step * x;
    const uint i = voxel_index(l);
    uint d = load_cost(p.dst, i);
    if (d == 0u) next = x;
    if (next >= 0) d = min(d, uint(next - x));
    if (d != VF_INF && h.metric == VF_EUCLIDEAN) d = d * d;
    store_cost(p.dst, i, d);
  }
}
