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
  const int top = p.storage == VF_U8 ? 255 : 65535;
  return uint(clamp(v, 0, top));
}

void main() {
  const uint i = invocation();
  const ivec3 n = p.domain_size.xyz;
  if (i >= uint(n.x * n.y * n.z)) return;
  const ivec3 l = ivec3(int(i) % n.x, (int(i) / n.x) % n.y, int(i) / (n.x * n.y));
  const bool inside = p.is_signed != 0u && material_at(p.domain_begin.xyz + l) != 0u;
  const uint cost = inside ? load_cost(p.src2, i) : load_cost(p.src, i);
  uint stored;
  if (cost == VF_INF) {
    stored = inside ? p.none_neg : p.none_pos;
  } else if (cost >= p.clamp_cost) {
    stored = inside ? p.clamp_neg : p.clamp_pos;
  } else if (p.storage == VF_F32) {
    const float d = p.metric == VF_EUCLIDEAN ? sqrt(float(cost)) : float(cost);
    stored = floatBitsToUint(inside ? -d : d);
  } else if (p.metric == VF_EUCLIDEAN) {
    const uint m = cost * p.scale_sq;  // the host checked that this fits 32 bits
    const uint r = isqrt(m);
    const int scaled = inside ? -int(r + (r * r != m ? 1u : 0u)) : int(r);
    stored = clamp_storage(scaled + p.bias);
  } else {
    stored = clamp_storage((inside ? -int(cost) : int(cost)) + p.bias);
  }
  out_values[i] = stored;
}
