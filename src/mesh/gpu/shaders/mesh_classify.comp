// voxfield — marching cubes on the GPU, pass 1: classify (Nässén & Leiborn 2019, after Dyken et
// al. 2007). Each cell finds its corner mask, settles its ambiguous faces by the asymptotic
// decider (Nielson & Hamann 1991) from the face's own four samples — as the CPU does, so both
// cells sharing a face decide alike — and writes its triangle count (the pyramid's level 0) and
// its case.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "mesh_common.glsl"

layout(std430, set = 0, binding = 4) writeonly buffer Pyramid { uint pyramid[]; };
layout(std430, set = 0, binding = 5) writeonly buffer Cases { uint cell_case[]; };

layout(local_size_x = 64) in;

void classify(uint cell) {
  const ivec3 at = cell_of(cell);
  float raw[8];
  uint inside = 0u;
  for (uint k = 0u; k < 8u; ++k) {
    raw[k] = raw_value(at + corner_offset(k));
    if (is_inside(raw[k])) inside |= 1u << k;
  }
  if (inside == 0u || inside == 255u) {
    pyramid[cell] = 0u;
    return;
  }
  float v[8];
  for (uint k = 0u; k < 8u; ++k) v[k] = s_of(raw[k]);
  const uint ambiguous = tables[VF_MC_AMBIGUOUS + int(inside)];
  uint joined = 0u, bit = 0u;
  for (uint face = 0u; face < 6u; ++face) {
    if (((ambiguous >> face) & 1u) == 0u) continue;
    const uint base = uint(VF_MC_FACES) + 4u * face;
    const uint c0 = tables[base], c1 = tables[base + 1u], c2 = tables[base + 2u],
               c3 = tables[base + 3u];
    precise double d02 = double(v[c0]) * double(v[c2]);
    precise double d13 = double(v[c1]) * double(v[c3]);
    const bool diagonal02_inside = ((inside >> c0) & 1u) != 0u;
    if (diagonal02_inside ? d13 >= d02 : d02 >= d13) joined |= 1u << bit;
    ++bit;
  }
  const uint index = tables[VF_MC_OFFSETS + int(inside)] + joined;
  pyramid[cell] = tables[uint(VF_MC_CASES) + uint(VF_MC_CASE_WORDS) * index];
  cell_case[cell] = index;
}

void main() {
  const ivec3 c = p.cells.xyz;
  const uint cells = uint(c.x * c.y * c.z);
  // A grid-stride loop: the dispatch is at most the device's x limit of workgroups.
  for (uint cell = gl_GlobalInvocationID.x; cell < cells; cell += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    classify(cell);
}
