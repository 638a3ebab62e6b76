// The decay and blend of a dynamic field's step (Hamlin, "Volumetric Interaction", section 3.3):
// the previous texel loses decay_s of its strength, and the current one is blended with what
// remains, weighted by strength. blend() is the definition, one texel at a time; on x86-64,
// Rgba8Blend4 computes it for four rgba8 texels at once, operation for operation the same
// IEEE float arithmetic (divps, sqrtps and mulps round exactly as their scalar forms do, and no
// multiply-add is fused: -ffp-contract=off), so its bytes equal blend() then store() bit for bit.
// The step's sweep spends most of its time in this arithmetic's two divisions and square root;
// four lanes share each.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "texel_codec.h"
#include "voxfield/vectors.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#define VOXFIELD_VECTORS_BLEND4 1
#endif

namespace voxfield::detail::vectors {

// The blend of one texel, in float as a shader blends (the texels are floats or narrower).
inline VectorTexel blend(const VectorTexel& current, const VectorTexel& previous, float decay_s) {
  const float sc = current.strength;
  const float sp = std::max(0.0f, previous.strength - decay_s);
  const float total = sc + sp;
  // Both gone (or decayed away): the zero texel, as where no source ever was — not the old
  // direction at strength 0, which would keep a stale direction in the texture.
  if (!(total > 0)) return {};
  // One side alone: its direction as stored (renormalising a decoded 8-bit direction every step
  // would let it drift), with the decayed strength.
  if (sp == 0) return current;
  if (sc == 0) return {previous.x, previous.y, previous.z, sp};
  const float w = sc / total;
  const float nx = w * current.x + (1 - w) * previous.x, ny = w * current.y + (1 - w) * previous.y,
              nz = w * current.z + (1 - w) * previous.z;
  const float length2 = nx * nx + ny * ny + nz * nz;
  VectorTexel out;
  if (length2 > 0) {
    const float inv = 1.0f / std::sqrt(length2);
    out.x = nx * inv;
    out.y = ny * inv;
    out.z = nz * inv;
  }
  out.strength = std::max(sc, sp);
  return out;
}

#if VOXFIELD_VECTORS_BLEND4
// Four rgba8 blends whose both sides have strength (the current strength byte and the decayed
// previous strength are > 0: the general case of blend(); the one-sided cases are a copy of one
// side's bytes, which the sweep does itself). run() takes the texels' bytes as little-endian words
// and returns the four blended texels' words.
struct Rgba8Blend4 {
  // Component `shift` of four words, decoded through `table` (a gather from the tables, not from
  // floats just written: narrow stores feeding a wide load would stall on store forwarding).
  static __m128 decode(const std::array<float, 256>& table, const std::uint32_t words[4],
                       int shift) {
    return _mm_setr_ps(table[(words[0] >> shift) & 0xffu], table[(words[1] >> shift) & 0xffu],
                       table[(words[2] >> shift) & 0xffu], table[(words[3] >> shift) & 0xffu]);
  }

  // unorm8 of four lanes: clamped to [0, 1] (NaN to 0: maxps returns its second operand when
  // unordered), times 255 plus 1/2, truncated.
  static __m128i unorm8(__m128 v) {
    const __m128 c = _mm_min_ps(_mm_max_ps(v, _mm_setzero_ps()), _mm_set1_ps(1.0f));
    return _mm_cvttps_epi32(_mm_add_ps(_mm_mul_ps(c, _mm_set1_ps(255.0f)), _mm_set1_ps(0.5f)));
  }
  // A direction component's byte: unorm8((v + 1) / 2), as Codec<kRgba8>::store.
  static __m128i direction8(__m128 v) {
    return unorm8(_mm_mul_ps(_mm_add_ps(v, _mm_set1_ps(1.0f)), _mm_set1_ps(0.5f)));
  }

  static void run(const std::uint32_t current[4], const std::uint32_t previous[4], float decay_s,
                  std::uint32_t out[4]) {
    const Rgba8Tables& t = rgba8_tables();
    const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    const __m128 sc = decode(t.strength, current, 24);
    // max(0, s - decay): maxps(x, 0) is x > 0 ? x : 0, as std::max(0.0f, x) for every x.
    const __m128 sp =
        _mm_max_ps(_mm_sub_ps(decode(t.strength, previous, 24), _mm_set1_ps(decay_s)), zero);
    const __m128 w = _mm_div_ps(sc, _mm_add_ps(sc, sp));
    const __m128 rest = _mm_sub_ps(one, w);
    const __m128 nx = _mm_add_ps(_mm_mul_ps(w, decode(t.direction, current, 0)),
                                 _mm_mul_ps(rest, decode(t.direction, previous, 0)));
    const __m128 ny = _mm_add_ps(_mm_mul_ps(w, decode(t.direction, current, 8)),
                                 _mm_mul_ps(rest, decode(t.direction, previous, 8)));
    const __m128 nz = _mm_add_ps(_mm_mul_ps(w, decode(t.direction, current, 16)),
                                 _mm_mul_ps(rest, decode(t.direction, previous, 16)));
    const __m128 length2 =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(nx, nx), _mm_mul_ps(ny, ny)), _mm_mul_ps(nz, nz));
    // Where length2 is 0 (opposite directions cancelling) the direction is zero: the lane's
    // 0 * inf = NaN is masked away rather than stored.
    const __m128 some = _mm_cmpgt_ps(length2, zero);
    const __m128 inv = _mm_div_ps(one, _mm_sqrt_ps(length2));
    const __m128 x = _mm_and_ps(some, _mm_mul_ps(nx, inv));
    const __m128 y = _mm_and_ps(some, _mm_mul_ps(ny, inv));
    const __m128 z = _mm_and_ps(some, _mm_mul_ps(nz, inv));
    // max(sc, sp): maxps(sc, sp) is sc > sp ? sc : sp, the same value as std::max.
    const __m128 strength = _mm_max_ps(sc, sp);
    const __m128i word = _mm_or_si128(
        _mm_or_si128(direction8(x), _mm_slli_epi32(direction8(y), 8)),
        _mm_or_si128(_mm_slli_epi32(direction8(z), 16), _mm_slli_epi32(unorm8(strength), 24)));
    _mm_storeu_si128(reinterpret_cast<__m128i*>(out), word);
  }
};
#endif

}  // namespace voxfield::detail::vectors
