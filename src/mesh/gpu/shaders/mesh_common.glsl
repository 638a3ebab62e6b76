// voxfield shaders — what the marching-cubes passes share (src/mesh/gpu): the bindings, the
// samples in their three widths, and src/mesh/marching_cubes.cpp's arithmetic in the same order.
//
// The CPU computes crossings, gradients and normals in doubles from float samples; every
// intermediate here is `precise`, so nothing is fused or reordered, and with correctly rounded
// division and square root (lavapipe, desktop GPUs' double units) each vertex is the CPU's bit for
// bit.
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

// The samples, x fastest: floats, or codes (code * step) packed two or four per word.
layout(std430, set = 0, binding = 0) readonly buffer Samples { uint samples[]; };
layout(std430, set = 0, binding = 1) readonly buffer Tables { uint tables[]; };
// frame[0] = (origin xyz, step), frame[1] = (spacing xyz, 0).
layout(std430, set = 0, binding = 2) readonly buffer Frame { dvec4 frame[]; };
// Per pyramid level: (offset into the pyramid, dims x, y, z); level 0 counts each cell.
layout(std430, set = 0, binding = 3) readonly buffer Levels { ivec4 levels[]; };

layout(push_constant) uniform Push { MeshParams p; };

uint sample_index(ivec3 v) {
  return uint(v.x) + uint(p.size.x) * (uint(v.y) + uint(p.size.y) * uint(v.z));
}

// The sample as the CPU decodes it: float(code * step) for the integer widths.
float raw_value(ivec3 v) {
  const uint i = sample_index(v);
  if (p.size.w == VF_MC_F32) return uintBitsToFloat(samples[i]);
  int code;
  if (p.size.w == VF_MC_I16)
    code = bitfieldExtract(int(samples[i >> 1u]), int((i & 1u) * 16u), 16);
  else
    code = bitfieldExtract(int(samples[i >> 2u]), int((i & 3u) * 8u), 8);
  precise double value = double(code) * frame[0].w;
  return float(value);
}

bool is_inside(float value) { return p.negate != 0u ? value > p.iso : value < p.iso; }

// Negative inside, >= 0 outside (Block::s_of).
float s_of(float value) {
  precise float s = p.negate != 0u ? p.iso - value : value - p.iso;
  return s;
}

float s_at(ivec3 v) { return s_of(raw_value(v)); }

ivec3 cell_of(uint i) {
  const ivec3 c = p.cells.xyz;
  return ivec3(int(i % uint(c.x)), int((i / uint(c.x)) % uint(c.y)), int(i / uint(c.x * c.y)));
}

ivec3 corner_offset(uint c) { return ivec3(int(c & 1u), int((c >> 1u) & 1u), int((c >> 2u) & 1u)); }
