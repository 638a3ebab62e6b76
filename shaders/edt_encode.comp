// voxfield — last pass of the exact distance transform: turns the costs the separable passes
// left (distance, or squared distance for L2) into stored values, exactly as the CPU's encoder
// does (docs/distance.md): clamped, fixed point rounded down, offset binary for signed integer
// storage. Values that need real-number rounding (the clamp, "no site") come precomputed from
// the host; Euclidean fixed point is floor(sqrt(cost * S^2)) in integers, as on the CPU.
#version 450
#include "common.glsl"

uint isqrt(uint n) {
  uint r = uint(sqrt(float(n)));
  while (r > 0u && r * r > n) --r;
  while (r < 65535u && (r + 1u) * (r + 1u) <= n) ++r;
  return r;
}

uint clamp_storage(int v) {
  const int top = h.storage == VF_U8 ? 255 : 65535;
  return uint(clamp(v, 0, top));
}

// One invocation per voxel of the out box: its cost (relative to the compute box) becomes the
// stored value at its place in the resident field.
void main() {
  const uint i = invocation();
  const ivec3 n = p.out_size.xyz;
  if (i >= uint(n.x * n.y * n.z)) return;
  const ivec3 v = p.out_begin.xyz + ivec3(int(i) % n.x, (int(i) / n.x) % n.y, int(i) / (n.x * n.y));
  const uint c = voxel_index(v - p.box_begin.xyz);
  const bool inside = h.is_signed != 0u && material_at(v) != 0u;
  const uint cost = inside ? load_cost(p.src2, c) : load_cost(p.src, c);
  uint stored;
  if (cost == VF_INF) {
    stored = inside ? h.none_neg : h.none_pos;
  } else if (cost >= h.clamp_cost) {
    stored = inside ? h.clamp_neg : h.clamp_pos;
  } else if (h.storage == VF_F32) {
    const float d = h.metric == VF_EUCLIDEAN ? sqrt(float(cost)) : float(cost);
    stored = floatBitsToUint(inside ? -d : d);
  } else if (h.metric == VF_EUCLIDEAN) {
    const uint m = cost * h.scale_sq;  // the host checked that this fits 32 bits
    const uint r = isqrt(m);
    const int scaled = inside ? -int(r + (r * r != m ? 1u : 0u)) : int(r);
    stored = clamp_storage(scaled + h.bias);
  } else {
    stored = clamp_storage((inside ? -int(cost) : int(cost)) + h.bias);
  }
  const ivec3 f = v - h.field_begin.xyz;
  field_values[uint((f.z * h.field_size.y + f.y) * h.field_size.x + f.x)] = stored;
}
