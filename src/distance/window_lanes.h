// voxfield — the unit-spacing Euclidean line transform as a min-plus convolution over a window
// that follows the distance itself, on several lines side by side (internal).
//
// Each line asks out[x] = min_i f[i] + (x - i)² (Felzenszwalb & Huttenlocher, "Distance
// transforms of sampled functions", Theory of Computing 8, 2012). The lower-envelope scan does it
// in linear time whatever the distances, but it is a chain of dependent, data-dependent steps
// (~10 cycles per voxel on the profile of a 256³ transform). The minimum can also be taken over
// a window: only sites i with (x - i)² <= out[x] can be the minimum, and out[x] is bounded by its
// neighbour's, sqrt(out[x]) <= sqrt(out[x - 1]) + 1 (keep the neighbour's nearest site: it is at
// most one voxel farther from x). So the window at x reaches floor(sqrt(out[x - 1])) + 1 voxels
// each way — a few voxels near surfaces and inside solid matter, which is most of a real volume —
// and every step of it is an add and a min over W lines at once, without branches, when the W lines
// lie side by side in memory (lane k of element i at f[i * stride + k]): the columns of a row-major
// slice, the rows of a column-major one. That is the truncated min-convolution of
// truncated_min_convolution.h with a reach read from the field as it goes instead of a clamp.
//
// The window is the widest of the W lanes', and far from every site (open air) it grows past
// what the envelope costs: the caller gives a budget of window steps per line and, when it is
// spent, solves those lines with the envelope instead (window_lines_or_envelope).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "line_transforms.h"

#if defined(__SSE4_1__)
#include <smmintrin.h>
#endif

namespace voxfield::detail {

// Lines solved side by side by window_min_plus_lanes, one 32-bit lane each.
inline constexpr int kWindowLanes = 16;

// Sixteen 32-bit lanes: in SSE4.1 registers where the build targets it (the default x86-64-v2),
// in plain loops otherwise (a build for baseline x86-64; the tests run both). Sixteen, not the
// eight of two registers: each voxel's window waits on the one before (its reach is a square root
// and a maximum over the lanes of the previous result), and that chain, not the window's adds and
// mins, bounds the transform; sixteen lines share one chain. Measured, one thread, 256³ spheres
// and terrain (docs/benchmarks.md): 8 lanes 287-289 / 218-220 ms, 16 lanes 242-248 / 186-190,
// 32 lanes 261-263 / 185-192 (the windows, the widest of the lanes', grow with more lanes).
struct ScalarLanes {
  std::int32_t v[kWindowLanes];
  static ScalarLanes splat(std::int32_t x) {
    ScalarLanes r;
    for (auto& e : r.v) e = x;
    return r;
  }
  static ScalarLanes load(const std::int32_t* p) {
    ScalarLanes r;
    for (int k = 0; k < kWindowLanes; ++k) r.v[k] = p[k];
    return r;
  }
  void store(std::int32_t* p) const {
    for (int k = 0; k < kWindowLanes; ++k) p[k] = v[k];
  }
  friend ScalarLanes min(ScalarLanes x, ScalarLanes y) {
    for (int k = 0; k < kWindowLanes; ++k) x.v[k] = std::min(x.v[k], y.v[k]);
    return x;
  }
  friend ScalarLanes operator+(ScalarLanes x, ScalarLanes y) {
    for (int k = 0; k < kWindowLanes; ++k) x.v[k] += y.v[k];
    return x;
  }
  friend ScalarLanes operator&(ScalarLanes x, ScalarLanes y) {
    for (int k = 0; k < kWindowLanes; ++k) x.v[k] &= y.v[k];
    return x;
  }
  friend ScalarLanes operator>(ScalarLanes x, ScalarLanes y) {
    for (int k = 0; k < kWindowLanes; ++k) x.v[k] = x.v[k] > y.v[k] ? -1 : 0;
    return x;
  }
  bool none() const {
    std::int32_t any = 0;
    for (std::int32_t e : v) any |= e;
    return any == 0;
  }
  ScalarLanes isqrt() const {
    ScalarLanes r;
    for (int k = 0; k < kWindowLanes; ++k) {
      std::int64_t s = static_cast<std::int64_t>(std::sqrt(static_cast<double>(v[k])));
      s += (s + 1) * (s + 1) <= v[k];
      s -= s * s > v[k];
      r.v[k] = static_cast<std::int32_t>(s);
    }
    return r;
  }
  std::int32_t max_lane() const { return *std::max_element(v, v + kWindowLanes); }
};

#if defined(__SSE4_1__)
struct SseLanes {
  static constexpr int R = kWindowLanes / 4;  // registers of four lanes
  __m128i r[R];
  // The lanes from f(register), register by register.
  template <class F>
  static SseLanes each(F&& f) {
    SseLanes out;
    for (int k = 0; k < R; ++k) out.r[k] = f(k);
    return out;
  }
  static SseLanes splat(std::int32_t v) {
    return each([&](int) { return _mm_set1_epi32(v); });
  }
  static SseLanes load(const std::int32_t* p) {
    return each(
        [&](int k) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 4 * k)); });
  }
  void store(std::int32_t* p) const {
    for (int k = 0; k < R; ++k) _mm_storeu_si128(reinterpret_cast<__m128i*>(p + 4 * k), r[k]);
  }
  friend SseLanes min(SseLanes x, SseLanes y) {
    return each([&](int k) { return _mm_min_epi32(x.r[k], y.r[k]); });
  }
  friend SseLanes operator+(SseLanes x, SseLanes y) {
    return each([&](int k) { return _mm_add_epi32(x.r[k], y.r[k]); });
  }
  friend SseLanes operator&(SseLanes x, SseLanes y) {
    return each([&](int k) { return _mm_and_si128(x.r[k], y.r[k]); });
  }
  friend SseLanes operator>(SseLanes x, SseLanes y) {  // all ones where x > y
    return each([&](int k) { return _mm_cmpgt_epi32(x.r[k], y.r[k]); });
  }
  bool none() const {
    __m128i a = r[0];
    for (int k = 1; k < R; ++k) a = _mm_or_si128(a, r[k]);
    return _mm_testz_si128(a, a) != 0;
  }
  // floor(sqrt(v)) per lane for 0 <= v < 2^30: the float root (v above 2^24 rounds when
  // converted) raised by one where it fell short, lowered by one where it came out above (v just
  // below a square rounds up to it).
  SseLanes isqrt() const {
    return each([&](int k) {
      const __m128i v = r[k];
      __m128i q = _mm_cvttps_epi32(_mm_sqrt_ps(_mm_cvtepi32_ps(v)));
      const __m128i q1 = _mm_add_epi32(q, _mm_set1_epi32(1));
      const __m128i fine = _mm_cmpgt_epi32(_mm_mullo_epi32(q1, q1), v);
      q = _mm_sub_epi32(q, _mm_andnot_si128(fine, _mm_set1_epi32(-1)));
      return _mm_add_epi32(q, _mm_cmpgt_epi32(_mm_mullo_epi32(q, q), v));
    });
  }
  std::int32_t max_lane() const {
    __m128i m = r[0];
    for (int k = 1; k < R; ++k) m = _mm_max_epi32(m, r[k]);
    m = _mm_max_epi32(m, _mm_shuffle_epi32(m, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm_max_epi32(m, _mm_shuffle_epi32(m, _MM_SHUFFLE(2, 3, 0, 1)));
    return _mm_cvtsi128_si32(m);
  }
};
using Lanes = SseLanes;
#else
using Lanes = ScalarLanes;
#endif

// kWindowLanes lines of n voxels, lane k of element i at f[i * f_stride + k], into
// out[i * out_stride + k]: out = min(kInf, min_i f[i] + (x - i)²) with kInf =
// EuclideanInt32::kInf — the envelope's values, except that a cost of kInf or more (no site, or
// none within reach of the 32-bit costs) reads kInf, where the envelope may give kInf + d²: both
// are "no site" to every reader. Values only (no nearest sites). The costs must be 0 <= f <=
// kInf and n² < 2^29 (EuclideanInt32's range). Returns false, with out partly written, once the
// windows have cost more than `budget` steps (a step: one element of each lane read); true when
// every lane is solved.
template <class L = Lanes>
bool window_min_plus_lanes(int n, const std::int32_t* f, std::size_t f_stride, std::int32_t* out,
                           std::size_t out_stride, std::int64_t budget) {
  constexpr std::int32_t kInf = EuclideanInt32::kInf;
  L lowest = L::splat(kInf);
  for (int i = 0; i < n; ++i)
    lowest = min(lowest, L::load(f + static_cast<std::size_t>(i) * f_stride));
  // Lanes with a site have finite results everywhere, the others none: only the former bound the
  // window (live: all ones in them).
  const L live = L::splat(kInf) > lowest;
  if (live.none()) {
    for (int i = 0; i < n; ++i)
      L::splat(kInf).store(out + static_cast<std::size_t>(i) * out_stride);
    return true;
  }
  int reach = n - 1;  // the first voxel looks along the whole line
  for (int x = 0; x < n; ++x) {
    const int left = std::min(reach, x), right = std::min(reach, n - 1 - x);
    budget -= left + right + 1;
    if (budget < 0) return false;
    const std::int32_t* fx = f + static_cast<std::size_t>(x) * f_stride;
    L best = L::load(fx);
    const int both = std::min(left, right);
    for (int d = 1; d <= both; ++d) {
      const std::size_t o = static_cast<std::size_t>(d) * f_stride;
      best = min(best, min(L::load(fx - o), L::load(fx + o)) + L::splat(d * d));
    }
    for (int d = both + 1; d <= left; ++d)
      best = min(best, L::load(fx - static_cast<std::size_t>(d) * f_stride) + L::splat(d * d));
    for (int d = both + 1; d <= right; ++d)
      best = min(best, L::load(fx + static_cast<std::size_t>(d) * f_stride) + L::splat(d * d));
    best = min(best, L::splat(kInf));
    best.store(out + static_cast<std::size_t>(x) * out_stride);
    // The next window: floor(sqrt(best)) + 1 over the lanes with a site.
    reach = (best.isqrt() & live).max_lane() + 1;
  }
  return true;
}

// `count` lines of n voxels interleaved with lane stride 1 and element stride `stride`
// (f[i * stride + line]), solved W at a time through window_min_plus_lanes; a group whose windows
// outgrow `steps_per_voxel` window steps per voxel on average, and the last count % W lines,
// through the lower envelope (`envelope`: solve_lines-like, on `lines` contiguous lines of n) after
// copying them out into `scratch_in` / `scratch_out` (W * n entries each). After a group fails, the
// next `kGroupsAfterGivingUp` groups go to the envelope at once: neighbouring lines see much the
// same distances.
template <class Envelope>
void window_lines_or_envelope(int count, int n, const std::int32_t* f, std::size_t stride,
                              std::int32_t* out, std::int64_t steps_per_voxel,
                              std::int32_t* scratch_in, std::int32_t* scratch_out,
                              const Envelope& envelope) {
  constexpr int W = kWindowLanes;
  constexpr int kGroupsAfterGivingUp = 3;
  const auto through_envelope = [&](int first, int lines) {
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < lines; ++k)
        scratch_in[static_cast<std::size_t>(k) * n + i] =
            f[static_cast<std::size_t>(i) * stride + first + k];
    envelope(lines, n, scratch_in, scratch_out);
    for (int i = 0; i < n; ++i)
      for (int k = 0; k < lines; ++k)
        out[static_cast<std::size_t>(i) * stride + first + k] =
            scratch_out[static_cast<std::size_t>(k) * n + i];
  };
  int rest = 0;
  int line = 0;
  for (; line + W <= count; line += W) {
    if (rest > 0) {
      --rest;
    } else if (window_min_plus_lanes(n, f + line, stride, out + line, stride,
                                     steps_per_voxel * n)) {
      continue;
    } else {
      rest = kGroupsAfterGivingUp;
    }
    through_envelope(line, W);
  }
  if (line < count) through_envelope(line, count - line);
}

}  // namespace voxfield::detail
