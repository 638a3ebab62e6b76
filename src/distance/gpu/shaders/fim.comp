// voxfield — the Fast Iterative Method (Jeong & Whitaker, "A fast iterative method for eikonal
// equations", SIAM J. Sci. Comput. 2008) on the GPU, as Jacobi passes: every voxel of the region
// takes min(its value, the local rule over the previous pass's neighbours) — the CPU's rules of
// src/distance/family/fast_iterative.cpp:
//   Manhattan  min over the 6 face neighbours of (d + 1);
//   Chebyshev  min over the 26 neighbours of (d + 1);
//   Euclidean  the Godunov upwind solution of |grad d| = 1 (solved relative to the smallest
//              neighbour, which keeps float precision where the CPU's double formula would not).
// Convergence without read-back: the host records a generous number of passes, each followed by
// a one-invocation control pass; once a pass moves no voxel by more than eps, the control pass
// sets the next update's indirect workgroup count to zero, so the remaining passes do nothing.
// A final resolve pass brings the last written half to the front.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "split_buffer.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 1) buffer Control { uint control[]; };

layout(push_constant) uniform Push { FimParams p; };

// Both halves of the ping-pong in four windows of 2^p.region_begin.w words (a large domain's
// outgrow one binding).
VF_SPLIT_WORDS(, Values, value_words, 0, 2, 3, 4);
VF_SPLIT_LOAD(value_words, uint(p.region_begin.w))
VF_SPLIT_STORE(value_words, uint(p.region_begin.w))
float value(uint e) { return uintBitsToFloat(value_words(e)); }

float infinity() { return uintBitsToFloat(0x7F800000u); }  // the CPU's kFar

uint index_of(ivec3 q, ivec3 n) { return uint((q.z * n.y + q.y) * n.x + q.x); }
bool inside(ivec3 q, ivec3 n) { return all(greaterThanEqual(q, ivec3(0))) && all(lessThan(q, n)); }

float neighbour_rule(ivec3 v, ivec3 n) {
  float best = infinity();
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int l1 = abs(dx) + abs(dy) + abs(dz);
        if (l1 == 0 || (p.metric == VF_MANHATTAN && l1 != 1)) continue;
        const ivec3 q = v + ivec3(dx, dy, dz);
        if (inside(q, n)) best = min(best, value(p.src + index_of(q, n)) + 1.0);
      }
  return best;
}

float eikonal_rule(ivec3 v, ivec3 n) {
  float a[3];
  for (int axis = 0; axis < 3; ++axis) {
    a[axis] = infinity();
    for (int s = -1; s <= 1; s += 2) {
      ivec3 q = v;
      q[axis] += s;
      if (inside(q, n)) a[axis] = min(a[axis], value(p.src + index_of(q, n)));
    }
  }
  // Sort ascending.
  if (a[1] < a[0]) { const float t = a[0]; a[0] = a[1]; a[1] = t; }
  if (a[2] < a[1]) { const float t = a[1]; a[1] = a[2]; a[2] = t; }
  if (a[1] < a[0]) { const float t = a[0]; a[0] = a[1]; a[1] = t; }
  if (isinf(a[0])) return infinity();
  // w = u - a0 solves sum over the first k axes of (w - b_i)^2 = 1 with b_i = a_i - a0 >= 0.
  float w = 1.0;
  for (int k = 2; k <= 3; ++k) {
    const float bk = a[k - 1] - a[0];
    if (w <= bk) break;
    float B = 0.0, C = -1.0;
    for (int i = 0; i < k; ++i) {
      const float b = a[i] - a[0];
      B += b;
      C += b * b;
    }
    const float disc = B * B - float(k) * C;
    if (disc < 0.0) break;
    w = (B + sqrt(disc)) / float(k);
  }
  return a[0] + w;
}

void main() {
  const int mode = p.size.w;
  if (mode == VF_FIM_CONTROL) {
    if (gl_GlobalInvocationID.x != 0u) return;
    if (control[VF_FIM_GROUPS] != 0u) {  // the update pass before this one ran
      control[VF_FIM_LAST] = p.dst;
      control[VF_FIM_PASSES] += 1u;
      if (control[VF_FIM_MOVED] == 0u) {
        control[VF_FIM_CONVERGED] = 1u;
        control[VF_FIM_GROUPS] = 0u;
      }
      control[VF_FIM_MOVED] = 0u;
    }
    return;
  }
  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  const ivec3 n = p.size.xyz;
  if (i >= uint(n.x * n.y * n.z)) return;
  if (mode == VF_FIM_RESOLVE) {
    const uint last = control[VF_FIM_LAST];
    if (last != 0u) value_words_store(i, value_words(last + i));
    return;
  }
  const ivec3 v = ivec3(int(i) % n.x, (int(i) / n.x) % n.y, int(i) / (n.x * n.y));
  const float old = value(p.src + i);
  float d = old;
  // Sites (value 0) never change; nor do voxels outside the region.
  if (old != 0.0 && all(greaterThanEqual(v, p.region_begin.xyz)) && all(lessThan(v, p.region_end.xyz))) {
    const float u = p.metric == VF_EUCLIDEAN ? eikonal_rule(v, n) : neighbour_rule(v, n);
    if (u < old) d = u;
    if (old - d > p.eps) atomicOr(control[VF_FIM_MOVED], 1u);
  }
  value_words_store(p.dst + i, floatBitsToUint(d));
}
