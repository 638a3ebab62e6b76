// voxfield — one pass of the dissertation's value-propagating jump flooding, the CPU's
// src/distance/family/jump_flood_seed.cpp on the GPU: d(p) = min(d(p), d(p +- k e_i) + k) over the
// 6 axis neighbours at step k, reading the previous pass's values. The values are whole numbers
// (unit spacing), so float additions are exact and the result equals the CPU's bit for bit.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "split_buffer.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { JfaParams p; };

// Both halves of the ping-pong in one buffer: a pass reads [p.src, p.src + n) and writes at p.dst,
// in four windows of 2^p.size.w words (a large domain's outgrow one binding).
VF_SPLIT_WORDS(, Values, value_words, 0, 1, 2, 3);
VF_SPLIT_LOAD(value_words, uint(p.size.w))
VF_SPLIT_STORE(value_words, uint(p.size.w))
float value(uint e) { return uintBitsToFloat(value_words(e)); }

void main() {
  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  const ivec3 n = p.size.xyz;
  if (i >= uint(n.x * n.y * n.z)) return;
  const ivec3 v = ivec3(int(i) % n.x, (int(i) / n.x) % n.y, int(i) / (n.x * n.y));
  const int k = p.step;
  const float fk = float(k);
  const uint sy = uint(n.x), sz = uint(n.x * n.y);
  float d = value(p.src + i);
  if (v.x - k >= 0) d = min(d, value(p.src + i - uint(k)) + fk);
  if (v.x + k < n.x) d = min(d, value(p.src + i + uint(k)) + fk);
  if (v.y - k >= 0) d = min(d, value(p.src + i - uint(k) * sy) + fk);
  if (v.y + k < n.y) d = min(d, value(p.src + i + uint(k) * sy) + fk);
  if (v.z - k >= 0) d = min(d, value(p.src + i - uint(k) * sz) + fk);
  if (v.z + k < n.z) d = min(d, value(p.src + i + uint(k) * sz) + fk);
  value_words_store(p.dst + i, floatBitsToUint(d));
}
