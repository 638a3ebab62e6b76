// voxfield — one generation of a vector-field volume texture (src/vectors/generate.cpp on the GPU):
// each voxel finds its source (every source, its tile's sources, or jump flooding's winner) and
// writes the direction away from it and its strength, encoded in the texture's storage — the
// search and the conversion pass in one dispatch.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "vectors_common.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 7) writeonly buffer Texels { uint texels[]; };

void voxel(uint i) {
  const ivec3 v = voxel_of(i);
  const dvec3 centre = voxel_centre(v);
  const int w = find_winner(i, v, centre);
  const uvec4 texel = w >= 0 && w < p.size.w ? encode_texel(value_of(uint(w), centre)) : zero_texel();
  const uint words = words_per_texel(), at = i * words;
  for (uint k = 0u; k < words; ++k) texels[at + k] = texel[k];
}

void main() {
  const uint voxels = uint(p.size.x * p.size.y * p.size.z);
  for (uint i = gl_GlobalInvocationID.x; i < voxels; i += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    voxel(i);
}
