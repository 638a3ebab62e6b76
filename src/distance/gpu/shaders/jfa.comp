// voxfield — one pass of jump flooding (Rong & Tan, "Jump flooding in GPU with applications to
// Voronoi diagram and distance transform", I3D 2006), the CPU's src/distance/family/jump_flood.cpp
// on the GPU: each voxel looks at the 26 voxels p + k * {-1, 0, 1}^3 of the previous pass's
// buffer and keeps the nearest site, ties to the smaller (z, y, x) so the result does not depend
// on the order of the look-ups. Each pass is its own dispatch (it reads the whole previous pass).
// Sites are packed as (x | y << 16, z), VF_INF for none; integer costs (squared for Euclidean fit
// 32 bits below 32768 voxels per axis).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "split_buffer.glsl"

layout(local_size_x = 64) in;

layout(push_constant) uniform Push { JfaParams p; };

// Both halves of the ping-pong in one buffer: a pass reads sites [p.src, p.src + n) and writes at
// p.dst, two words a site, in four windows of 2^p.size.w words (a large domain's outgrow one
// binding).
VF_SPLIT_WORDS(, Sites, site_words, 0, 1, 2, 3);
VF_SPLIT_LOAD(site_words, uint(p.size.w))
VF_SPLIT_STORE(site_words, uint(p.size.w))
uvec2 site_at(uint e) { return uvec2(site_words(2u * e), site_words(2u * e + 1u)); }

uint cost(ivec3 d) {
  const uvec3 a = uvec3(abs(d));
  if (p.metric == VF_MANHATTAN) return a.x + a.y + a.z;
  if (p.metric == VF_CHEBYSHEV) return max(a.x, max(a.y, a.z));
  return a.x * a.x + a.y * a.y + a.z * a.z;
}

ivec3 unpack(uvec2 s) { return ivec3(int(s.x & 0xFFFFu), int(s.x >> 16), int(s.y)); }

bool smaller(ivec3 a, ivec3 b) {  // (z, y, x) order
  if (a.z != b.z) return a.z < b.z;
  if (a.y != b.y) return a.y < b.y;
  return a.x < b.x;
}

void main() {
  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  const ivec3 n = p.size.xyz;
  if (i >= uint(n.x * n.y * n.z)) return;
  const ivec3 v = ivec3(int(i) % n.x, (int(i) / n.x) % n.y, int(i) / (n.x * n.y));
  uvec2 best = site_at(p.src + i);
  uint best_cost = best.x == VF_INF ? VF_INF : cost(unpack(best) - v);
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const ivec3 q = v + ivec3(dx, dy, dz) * p.step;
        if (any(lessThan(q, ivec3(0))) || any(greaterThanEqual(q, n))) continue;
        const uvec2 s = site_at(p.src + uint((q.z * n.y + q.y) * n.x + q.x));
        if (s.x == VF_INF) continue;
        const uint c = cost(unpack(s) - v);
        if (c < best_cost || (c == best_cost && smaller(unpack(s), unpack(best)))) {
          best_cost = c;
          best = s;
        }
      }
  site_words_store(2u * (p.dst + i), best.x);
  site_words_store(2u * (p.dst + i) + 1u, best.y);
}
