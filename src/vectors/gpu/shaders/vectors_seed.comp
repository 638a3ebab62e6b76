// voxfield — jump flooding's seeding pass (src/vectors/jfa.cpp's seed on the GPU): one invocation
// per sample point along each source's segment (seed_span: half a voxel apart, so a source smaller
// than a voxel still seeds the voxel it is in and a fast mover seeds its trail). Two sources in one
// voxel are settled by their score at the voxel's centre, ties to the lower index — a total order,
// so the compare-and-swap loop below ends with the same winner in whatever order the samples land
// (the paper's seeding raced).
#version 450
#extension GL_GOOGLE_include_directive : require
#define VF_VECTORS_NO_SEARCH
#include "vectors_common.glsl"

layout(local_size_x = 64) in;

struct SeedSpan {
  dvec2 span;   // t0, t1
  uint first;   // the source's first sample among all sources' samples
  uint samples; // the points t = 0 .. samples
};
layout(std430, set = 0, binding = 3) readonly buffer Seeds { SeedSpan seeds[]; };
layout(std430, set = 0, binding = 4) coherent buffer Seeded { int seeded[]; };

// Whether source a beats source b at p (b >= 0).
bool beats(uint a, int b, dvec3 p) {
  dvec3 q;
  const double sa = score(distance_to(a, p, q), radius_of(a));
  const double sb = score(distance_to(uint(b), p, q), radius_of(uint(b)));
  return sa > sb || (sa == sb && int(a) < b);
}

void seed(uint g) {
  // The source this sample belongs to: the last whose first sample is at or before g.
  uint lo = 0u, hi = uint(p.size.w) - 1u;
  while (lo < hi) {
    const uint mid = (lo + hi + 1u) / 2u;
    if (seeds[mid].first <= g) lo = mid; else hi = mid - 1u;
  }
  const uint s = lo;
  const SeedSpan span = seeds[s];
  const uint t = g - span.first;
  if (span.samples == 0xffffffffu || t > span.samples) return;  // one that seeds nothing owns none
  const dvec4 a = segments[2u * s], ab = segments[2u * s + 1u];
  precise double along = span.span.x + (span.span.y - span.span.x) * (double(t) / double(span.samples));
  precise dvec3 point = a.xyz + ab.xyz * along;
  const dvec3 u = to_volume(point);
  const ivec3 n = p.size.xyz;
  ivec3 v;
  for (int k = 0; k < 3; ++k) {
    precise double scaled = u[k] * double(n[k]);
    v[k] = int(clamp(floor(scaled), 0.0LF, double(n[k] - 1)));
  }
  const uint at = uint(v.x + n.x * (v.y + n.y * v.z));
  const dvec3 centre = voxel_centre(v);
  int current = seeded[at];
  while (current != int(s) && (current < 0 || beats(s, current, centre))) {
    const int was = atomicCompSwap(seeded[at], current, int(s));
    if (was == current) break;
    current = was;
  }
}

void main() {
  for (uint g = gl_GlobalInvocationID.x; g < uint(p.pass.x); g += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    seed(g);
}
