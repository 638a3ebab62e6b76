// voxfield — marching cubes on the GPU, pass 2: one level of the HistoPyramid (Dyken, Ziegler,
// Theobalt & Seidel 2007), each element the sum of its children in the level below: four
// consecutive elements (the thesis's 4-to-1 pyramid, over the cells' linear order) or a 2 x 2 x 2
// block (the 3-D 8-to-1 variant). One dispatch per level, ordered by the recorder's barriers.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "mesh_common.glsl"

layout(std430, set = 0, binding = 4) buffer Pyramid { uint pyramid[]; };

layout(local_size_x = 64) in;

// Counts saturate: a total past 32 bits reads 0xffffffff, more than any vertex buffer holds, and
// is refused with the counts rather than wrapping to a small wrong one.
uint add_saturated(uint a, uint b) { return b > 0xffffffffu - a ? 0xffffffffu : a + b; }

void reduce(uint i, ivec4 below, ivec4 here) {
  uint sum = 0u;
  if (p.cells.w == VF_MC_PYRAMID_4) {
    for (uint j = 0u; j < 4u; ++j) {
      const uint child = 4u * i + j;
      if (child < uint(below.y)) sum = add_saturated(sum, pyramid[uint(below.x) + child]);
    }
  } else {
    const ivec3 at = ivec3(int(i % uint(here.y)), int((i / uint(here.y)) % uint(here.z)),
                           int(i / uint(here.y * here.z)));
    for (uint k = 0u; k < 8u; ++k) {
      const ivec3 child = 2 * at + corner_offset(k);
      if (child.x < below.y && child.y < below.z && child.z < below.w)
        sum = add_saturated(sum, pyramid[uint(below.x) +
                                         uint(child.x + below.y * (child.y + below.z * child.z))]);
    }
  }
  pyramid[uint(here.x) + i] = sum;
}

void main() {
  const ivec4 below = levels[p.pass.x - 1], here = levels[p.pass.x];
  const uint count = uint(here.y * here.z * here.w);
  // A grid-stride loop: the dispatch is at most the device's x limit of workgroups.
  for (uint i = gl_GlobalInvocationID.x; i < count; i += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    reduce(i, below, here);
}
