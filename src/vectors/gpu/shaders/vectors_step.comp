// voxfield — one step of a moving vector field (src/vectors/simulation.cpp on the GPU): each voxel
// finds its source and writes this step's texel, then blends it with the previous field's texel,
// decayed, into the next field — generation, decay and blend in one dispatch, as the CPU's fused
// sweep (Hamlin, "Volumetric Interaction", section 3.3).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "vectors_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 7) writeonly buffer Current { uint current[]; };
layout(std430, set = 0, binding = 8) readonly buffer Previous { uint previous[]; };
layout(std430, set = 0, binding = 9) writeonly buffer Next { uint next[]; };

void voxel(uint i) {
  const ivec3 v = voxel_of(i);
  const dvec3 centre = voxel_centre(v);
  const int w = find_winner(i, v, centre);
  const uint words = words_per_texel(), at = i * words;
  uvec4 before = uvec4(0u);
  for (uint k = 0u; k < words; ++k) before[k] = previous[at + k];
  uvec4 now_texel = zero_texel(), next_texel;
  if (w >= 0 && w < p.size.w) {
    now_texel = encode_texel(value_of(uint(w), centre));
    // The texel as stored, read back: the blend sees what the texture holds.
    next_texel = encode_texel(blend(decode_texel(now_texel), decode_texel(before), p.decay));
  } else if (zero_strength(before)) {
    next_texel = zero_texel();
  } else {
    next_texel = encode_texel(blend(vec4(0.0), decode_texel(before), p.decay));
  }
  for (uint k = 0u; k < words; ++k) {
    current[at + k] = now_texel[k];
    next[at + k] = next_texel[k];
  }
}

void main() {
  const uint voxels = uint(p.size.x * p.size.y * p.size.z);
  for (uint i = gl_GlobalInvocationID.x; i < voxels; i += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    voxel(i);
}
