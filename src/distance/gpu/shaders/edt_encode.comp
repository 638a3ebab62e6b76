// voxfield — last pass of the exact distance transform: turns the costs the separable passes
// left (distance, or squared distance for L2) into stored values, exactly as the CPU's encoder
// does (docs/distance.md): clamped, fixed point rounded down, offset binary for signed integer
// storage. Values that need real-number rounding (the clamp, "no site") come precomputed from
// the host; Euclidean fixed point is floor(sqrt(cost * S^2)) in integers, as on the CPU. u8 and
// u16 values are packed into the resident field as they are stored on the CPU: 1 and 2 bytes.
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

// The stored value of voxel v (world coordinates) from the costs of the compute box.
uint stored_value(ivec3 v) {
  const uint c = voxel_index(v - p.box_begin.xyz);
  const bool inside = h.is_signed != 0u && material_at(v) != 0u;
  const uint cost = inside ? load_cost(p.src2, c) : load_cost(p.src, c);
  if (cost == VF_INF) return inside ? h.none_neg : h.none_pos;
  if (cost >= h.clamp_cost) return inside ? h.clamp_neg : h.clamp_pos;
  if (h.storage == VF_F32) {
    const float d = h.metric == VF_EUCLIDEAN ? sqrt(float(cost)) : float(cost);
    return floatBitsToUint(inside ? -d : d);
  }
  if (h.metric == VF_EUCLIDEAN) {
    const uint m = cost * h.scale_sq;  // the host checked that this fits 32 bits
    const uint r = isqrt(m);
    const int scaled = inside ? -int(r + (r * r != m ? 1u : 0u)) : int(r);
    return clamp_storage(scaled + h.bias);
  }
  return clamp_storage((inside ? -int(cost) : int(cost)) + h.bias);
}

// The nearest site of voxel v (world coordinates) as offsets from v, in the field's site buffer
// (the CPU's rule: none when no site is within the clamp).
void store_site_offset(ivec3 v) {
  const uint c = voxel_index(v - p.box_begin.xyz);
  const bool inside = h.is_signed != 0u && material_at(v) != 0u;
  const uint from = inside ? p.src2 : p.src;
  const uint cost = load_cost(from, c);
  uvec2 packed = uvec2(0x80008000u, 0x8000u);  // SiteOffset::kNone (-32768) in all three
  if (cost != VF_INF && cost <= h.site_cost_max) {
    const ivec3 d = p.box_begin.xyz + unpack_site(load_site(from, c)) - v;
    packed = uvec2((uint(d.x) & 0xFFFFu) | (uint(d.y) << 16), uint(d.z) & 0xFFFFu);
  }
  const ivec3 f = v - h.field_begin.xyz;
  const uint at = 2u * uint((f.z * h.field_size.y + f.y) * h.field_size.x + f.x);
  field_site_words_store(at, packed.x);
  field_site_words_store(at + 1u, packed.y);
}

// The resident field is packed: 4 u8 or 2 u16 values per word along x (rows padded to
// field_size.w voxels, a whole number of words), so one invocation owns one word of the out box
// and keeps the lanes outside it — no two invocations write the same word.
void main() {
  const uint i = invocation();
  const int lanes = h.storage == VF_U8 ? 4 : h.storage == VF_U16 ? 2 : 1;
  const ivec3 o = p.out_begin.xyz - h.field_begin.xyz;  // the out box in field coordinates
  const int w0 = o.x / lanes, w1 = (o.x + p.out_size.x - 1) / lanes;
  const ivec3 n = ivec3(w1 - w0 + 1, p.out_size.y, p.out_size.z);
  if (i >= uint(n.x * n.y * n.z)) return;
  const int wx = w0 + int(i) % n.x, y = o.y + (int(i) / n.x) % n.y, z = o.z + int(i) / (n.x * n.y);
  const uint word_index = uint((z * h.field_size.y + y) * (h.field_size.w / lanes) + wx);
  if (lanes == 1) {
    field_values_store(word_index, stored_value(h.field_begin.xyz + ivec3(wx, y, z)));
    if (h.track_sites != 0u) store_site_offset(h.field_begin.xyz + ivec3(wx, y, z));
    return;
  }
  const uint bits = 32u / uint(lanes), mask = (1u << bits) - 1u;
  uint word = field_values(word_index);
  for (int j = 0; j < lanes; ++j) {
    const int x = wx * lanes + j;
    if (x < o.x || x >= o.x + p.out_size.x) continue;
    const uint shift = uint(j) * bits;
    word = (word & ~(mask << shift)) | ((stored_value(h.field_begin.xyz + ivec3(x, y, z)) & mask) << shift);
    if (h.track_sites != 0u) store_site_offset(h.field_begin.xyz + ivec3(x, y, z));
  }
  field_values_store(word_index, word);
}
