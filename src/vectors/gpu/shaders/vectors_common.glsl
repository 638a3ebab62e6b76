// voxfield shaders — what the vector-field passes share (src/vectors/gpu): the bindings, the model
// of docs/vectors.md in double precision, the texel codecs and the blend.
//
// The CPU computes distances, winners and directions in doubles (src/vectors/vector_internal.h)
// and encodes and blends in floats (texel_codec.h, simulation.cpp). These functions do the same
// operations in the same order, and every intermediate is `precise` so the compiler neither fuses
// a multiply into an add nor reorders a sum: with correctly rounded division and square roots
// (lavapipe, and the desktop GPUs' double units) each texel is the CPU's bit for bit.
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

// Sources as segments: segments[2 s] = (a, radius), segments[2 s + 1] = (b - a, |b - a|^2).
layout(std430, set = 0, binding = 0) readonly buffer Segments { dvec4 segments[]; };
// The volume and the voxel-centre tables (VF_VECTORS_TABLES).
layout(std430, set = 0, binding = 1) readonly buffer Centres { dvec4 centres[]; };

layout(push_constant) uniform Push { VectorParams p; };

// Every pass strides over its voxels (Recorder::dispatch_strided): for (i = gl_GlobalInvocationID.x;
// i < n; i += gl_NumWorkGroups.x * gl_WorkGroupSize.x).

ivec3 voxel_of(uint i) {
  const ivec3 n = p.size.xyz;
  return ivec3(int(i % uint(n.x)), int((i / uint(n.x)) % uint(n.y)), int(i / uint(n.x * n.y)));
}

// ((centre + z[k]) + y[j]) + x[i], as CentreTables::at.
dvec3 voxel_centre(ivec3 v) {
  precise dvec3 row = centres[0].xyz + centres[p.tables.z + v.z].xyz;
  precise dvec3 at = row + centres[p.tables.y + v.y].xyz;
  precise dvec3 c = at + centres[p.tables.x + v.x].xyz;
  return c;
}

double dot3(dvec3 a, dvec3 b) {  // a.x b.x + a.y b.y + a.z b.z, left to right (GLSL's dot() has no order)
  precise double xy = a.x * b.x + a.y * b.y;
  precise double d = xy + a.z * b.z;
  return d;
}

// VectorVolume::to_volume: the box's axes are centres[1..3], its size centres[4].
dvec3 to_volume(dvec3 world) {
  precise dvec3 d = world - centres[0].xyz;
  precise dvec3 u = dvec3(dot3(centres[1].xyz, d) / centres[4].x + 0.5LF,
                          dot3(centres[2].xyz, d) / centres[4].y + 0.5LF,
                          dot3(centres[3].xyz, d) / centres[4].z + 0.5LF);
  return u;
}

// distance_to: the nearest point q of segment s to p, and the distance.
double distance_to(uint s, dvec3 p, out dvec3 q) {
  const dvec4 a = segments[2u * s], ab = segments[2u * s + 1u];
  precise double t = 0.0LF;
  if (ab.w > 0.0LF) t = clamp(dot3(p - a.xyz, ab.xyz) / ab.w, 0.0LF, 1.0LF);
  precise dvec3 nearest = a.xyz + ab.xyz * t;
  q = nearest;
  precise dvec3 e = p - nearest;
  precise double d = sqrt(dot3(e, e));
  return d;
}

double radius_of(uint s) { return segments[2u * s].w; }

// Larger is better: 1 - d / r (strongest), -d (nearest).
double score(double d, double r) {
  precise double sc = p.rule == 0u ? 1.0LF - d / r : -d;
  return sc;
}

// The direction and strength of source s at p (vector_internal.h's value_of, then texel_of):
// zero when it does not cover p.
vec4 value_of(uint s, dvec3 p) {
  dvec3 q;
  const double d = distance_to(s, p, q), r = radius_of(s);
  if (!(d < r)) return vec4(0.0);
  precise double strength = 1.0LF - d / r;
  precise dvec3 direction = dvec3(0.0LF);
  if (d > 0.0LF) {
    precise double inv = 1.0LF / d;
    direction = (p - q) * inv;
  }
  return vec4(vec3(direction), float(strength));
}

// ---- texel codecs (texel_codec.h) ------------------------------------------------------------------
// rgba8: one word per texel, bytes r, g, b, a from the low end; rgba16f: two words; rgba32f: four.
uint words_per_texel() { return p.storage == 0u ? 1u : p.storage == 1u ? 2u : 4u; }

uint unorm8(float v) {
  const float c = v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0;
  precise float scaled = c * 255.0 + 0.5;
  return uint(scaled);
}

uint to_half(float f) {  // round to nearest even, as texel_codec.h's to_half
  const uint x = floatBitsToUint(f);
  const uint sign = (x >> 16) & 0x8000u;
  const uint a = x & 0x7fffffffu;
  if (a >= 0x7f800000u) return sign | (a > 0x7f800000u ? 0x7e00u : 0x7c00u);
  if (a >= 0x477ff000u) return sign | 0x7c00u;
  if (a < 0x38800000u) {
    precise float scaled = uintBitsToFloat(a) * 16777216.0;
    return sign | uint(roundEven(scaled));
  }
  const uint odd = (a >> 13) & 1u;
  return sign | ((a + 0xfffu + odd - 0x38000000u) >> 13);
}

float from_half(uint h) {
  const uint sign = (h & 0x8000u) << 16, exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
  if (exponent == 0u) {
    const float v = float(mantissa) / 16777216.0;
    return sign != 0u ? -v : v;
  }
  if (exponent == 31u) return uintBitsToFloat(sign | 0x7f800000u | (mantissa << 13));
  return uintBitsToFloat(sign | ((exponent + 112u) << 23) | (mantissa << 13));
}

uvec4 encode_texel(vec4 t) {
  if (p.storage == 0u) {
    precise vec3 shifted = (t.xyz + 1.0) * 0.5;
    return uvec4(unorm8(shifted.x) | (unorm8(shifted.y) << 8) | (unorm8(shifted.z) << 16) |
                     (unorm8(t.w) << 24), 0u, 0u, 0u);
  }
  if (p.storage == 1u)
    return uvec4(to_half(t.x) | (to_half(t.y) << 16), to_half(t.z) | (to_half(t.w) << 16), 0u, 0u);
  return floatBitsToUint(t);
}

uvec4 zero_texel() { return p.storage == 0u ? uvec4(0x00808080u, 0u, 0u, 0u) : uvec4(0u); }

bool zero_strength(uvec4 w) {
  if (p.storage == 0u) return (w.x >> 24) == 0u;
  if (p.storage == 1u) return ((w.y >> 16) & 0x7fffu) == 0u;
  return uintBitsToFloat(w.w) == 0.0;
}

// rgba8 decoding, as texel_codec.h's tables (computed once on the host, uploaded): [b] the
// direction component 2 b / 255 - 1, [256 + b] the strength b / 255.
layout(std430, set = 0, binding = 6) readonly buffer Decode8 { float decode8[]; };

vec4 decode_texel(uvec4 w) {
  if (p.storage == 0u)
    return vec4(decode8[w.x & 255u], decode8[(w.x >> 8) & 255u], decode8[(w.x >> 16) & 255u],
                decode8[256u + (w.x >> 24)]);
  if (p.storage == 1u)
    return vec4(from_half(w.x & 0xffffu), from_half(w.x >> 16), from_half(w.y & 0xffffu),
                from_half(w.y >> 16));
  return uintBitsToFloat(w);
}

// The decay and blend of one step (simulation.cpp's blend), in floats.
vec4 blend(vec4 current, vec4 previous, float decay_s) {
  const float sc = current.w;
  precise float sp = max(0.0, previous.w - decay_s);
  precise float total = sc + sp;
  if (!(total > 0.0)) return vec4(0.0);
  if (sp == 0.0) return current;
  if (sc == 0.0) return vec4(previous.xyz, sp);
  precise float w = sc / total;
  precise float wp = 1.0 - w;
  precise vec3 n = vec3(w * current.x + wp * previous.x, w * current.y + wp * previous.y,
                        w * current.z + wp * previous.z);
  precise float length2 = n.x * n.x + n.y * n.y + n.z * n.z;
  vec4 blended = vec4(0.0, 0.0, 0.0, max(sc, sp));
  if (length2 > 0.0) {
    precise float inv = 1.0 / sqrt(length2);
    precise vec3 unit = n * inv;
    blended.xyz = unit;
  }
  return blended;
}

#ifndef VF_VECTORS_NO_SEARCH  // the seeding pass binds the winners its own way
// ---- finding each voxel's source ----------------------------------------------------------------
// Splatting's bins: tiles[t] .. tiles[t + 1] index the sources (ascending) whose index boxes meet
// tile t; the lists follow the tile_count + 1 offsets.
layout(std430, set = 0, binding = 2) readonly buffer Tiles { uint tiles[]; };
// Jump flooding's winners (and brute force's and splatting's when asked for).
layout(std430, set = 0, binding = 4) readonly buffer WinnersIn { int winners_in[]; };
layout(std430, set = 0, binding = 5) writeonly buffer WinnersOut { int winners_out[]; };

// The definition's winner at p: the greatest score, ties to the lower index (brute.cpp, splat.cpp).
void consider_exact(uint s, dvec3 p, inout int best, inout double best_score) {
  dvec3 q;
  const double d = distance_to(s, p, q), r = radius_of(s);
  if (!(d < r)) return;
  const double sc = score(d, r);
  if (best < 0 || sc > best_score) {
    best = int(s);
    best_score = sc;
  }
}

int find_winner(uint i, ivec3 v, dvec3 centre) {
  if (p.search == VF_VECTORS_WINNERS) return winners_in[i];
  int best = -1;
  double best_score = 0.0LF;
  if (p.search == VF_VECTORS_BRUTE) {
    for (uint s = 0u; s < uint(p.size.w); ++s) consider_exact(s, centre, best, best_score);
  } else {
    const ivec3 t = v / VF_VECTORS_TILE;
    const uint tile = uint(t.x + p.tiles.x * (t.y + p.tiles.y * t.z));
    for (uint at = tiles[tile]; at < tiles[tile + 1u]; ++at) consider_exact(tiles[at], centre, best, best_score);
  }
  if ((p.flags & VF_VECTORS_WRITE_WINNERS) != 0u) winners_out[i] = best;
  return best;
}
#endif
