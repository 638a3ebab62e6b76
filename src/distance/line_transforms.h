// voxfield — one-dimensional exact distance transforms, the building block of the separable
// passes (internal).
//
// Each routine solves, on a line of n voxels,
//     out[x] = min over i of F(x, i),   arg[x] = the smallest minimising i (-1 when none),
// where F(x, i) combines the cost f[i] of the best site seen through voxel i by the previous
// passes with the step from i to x along this axis:
//     Euclidean  F = w (x - i)^2 + f[i]        (w = spacing^2 along this axis; f squared)
//     Chebyshev  F = max(|x - i|, f[i])
//     Manhattan  F = |x - i| + f[i]
// The Euclidean and Chebyshev routines are the lower-envelope scan of Meijster, Roerdink and
// Hesselink, "A general algorithm for computing distance transforms in linear time" (2000): a
// forward scan keeps the sites whose F is minimal somewhere, with the first voxel t[q] where site
// s[q] takes over; Sep(i, u) is the last x at which the earlier site i is still no worse than u.
// Because Sep keeps ties with the earlier site and a site is popped only when strictly worse,
// the smallest minimising index wins every tie. The unit-spacing Euclidean kernel in 32-bit costs,
// the common case, is the same envelope without divisions (envelope_euclidean_int32, below).
// Manhattan needs no envelope: a forward and a backward min-plus sweep (Rosenfeld & Pfaltz 1966)
// give the same result in two passes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace voxfield::detail {

// floor(a / b) for b > 0.
inline std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

// floor(a / b) for b > 0 without a libm call (baseline x86-64 has no rounding instruction).
inline std::int64_t floor_quotient(double a, double b) {
  const double q = a / b;
  const auto t = static_cast<std::int64_t>(q);
  return static_cast<double>(t) > q ? t - 1 : t;
}

// Euclidean with unit spacing: integer arithmetic, exact.
struct EuclideanInt {
  using Value = std::int64_t;
  static constexpr Value kInf = std::numeric_limits<std::int64_t>::max() / 4;
  static Value F(std::int64_t x, std::int64_t i, Value fi) { return (x - i) * (x - i) + fi; }
  // floor(a / b) through a double division: a and b are integers below 2^53, and a quotient within
  // 1/b of an integer from below stays below it after rounding (1/b >= 2^-16 here, far above the
  // double's relative error), so the floor is exact — and several times faster than idiv.
  static std::int64_t Sep(std::int64_t i, std::int64_t u, Value fi, Value fu) {
    return floor_quotient(static_cast<double>(u * u - i * i + fu - fi),
                          static_cast<double>(2 * (u - i)));
  }
};

// Euclidean with unit spacing in 32-bit integers, for domains whose largest squared distance
// (sum of squared extents) stays below 2^30: half the memory traffic of the 64-bit version.
struct EuclideanInt32 {
  using Value = std::int32_t;
  static constexpr Value kInf = std::numeric_limits<std::int32_t>::max() / 4;
  static Value F(std::int64_t x, std::int64_t i, Value fi) {
    const auto d = static_cast<std::int32_t>(x - i);
    return d * d + fi;
  }
  static std::int64_t Sep(std::int64_t i, std::int64_t u, Value fi, Value fu) {
    return EuclideanInt::Sep(i, u, fi, fu);
  }
};

// Euclidean with spacing: w = spacing^2 along the line.
struct EuclideanReal {
  using Value = double;
  static constexpr Value kInf = std::numeric_limits<double>::infinity();
  double w = 1;
  Value F(std::int64_t x, std::int64_t i, Value fi) const {
    const double d = static_cast<double>(x - i);
    return w * d * d + fi;
  }
  std::int64_t Sep(std::int64_t i, std::int64_t u, Value fi, Value fu) const {
    const double num = w * static_cast<double>(u * u - i * i) + fu - fi;
    const double sep = std::floor(num / (2.0 * w * static_cast<double>(u - i)));
    // Keep far-away crossings in range of int64; anything beyond the line is equivalent.
    return static_cast<std::int64_t>(std::clamp(sep, -1e15, 1e15));
  }
};

struct Chebyshev {
  using Value = std::int32_t;
  static constexpr Value kInf = std::numeric_limits<std::int32_t>::max() / 4;
  static Value F(std::int64_t x, std::int64_t i, Value fi) {
    return std::max(static_cast<Value>(x > i ? x - i : i - x), fi);
  }
  static std::int64_t Sep(std::int64_t i, std::int64_t u, Value fi, Value fu) {
    const std::int64_t mid = floor_div(i + u, 2);
    return fi <= fu ? std::max<std::int64_t>(i + fu, mid) : std::min<std::int64_t>(u - fi, mid);
  }
};

// Lower-envelope scan (Meijster et al. 2000, phase 2). s, t: scratch of n ints; arg may be null.
template <class Traits>
void envelope_1d(const Traits& tr, int n, const typename Traits::Value* f,
                 typename Traits::Value* out, std::int32_t* arg, std::int32_t* s, std::int32_t* t) {
  using Value = typename Traits::Value;
  int q = -1;
  Value fs = Value(0);  // f[s[q]], kept in a register
  for (int u = 0; u < n; ++u) {
    const Value fu = f[u];
    if (!(fu < Traits::kInf)) continue;
    while (q >= 0 && tr.F(t[q], s[q], fs) > tr.F(t[q], u, fu)) {
      --q;
      if (q >= 0) fs = f[s[q]];
    }
    if (q < 0) {
      q = 0;
      s[0] = u;
      t[0] = 0;
      fs = fu;
    } else {
      // No pop means s[q] is no worse than u at t[q], so u takes over after t[q]: exactly, Sep
      // >= t[q]. EuclideanReal's Sep is a rounded division, and at an exact tie it can land one
      // below (14.999... for 15), which would give s[q] an empty stretch that the write-back
      // loop below never leaves — the wrong site for every voxel before it.
      const std::int64_t w = std::max<std::int64_t>(1 + tr.Sep(s[q], u, fs, fu), t[q] + 1);
      if (w < n) {
        ++q;
        s[q] = u;
        t[q] = static_cast<std::int32_t>(w);
        fs = fu;
      }
    }
  }
  if (q < 0) {
    std::fill(out, out + n, Traits::kInf);
    if (arg) std::fill(arg, arg + n, -1);
    return;
  }
  for (int x = n - 1; x >= 0; --x) {
    const std::int32_t site = s[q];
    out[x] = tr.F(x, site, f[site]);
    if (arg) arg[x] = site;
    if (x == t[q]) --q;
  }
}

// The unit-spacing Euclidean envelope in 32-bit costs without a single division (the kernel of
// the common case: domains whose largest squared distance is below 2^29, EuclideanInt32).
// Write each site's parabola as P_u(x) = x^2 - 2ux + h_u with its height h_u = u^2 + f[u]; two
// of them cross at X(a, b) = (h_b - h_a) / (2 (b - a)), and b is strictly lower than a (a < b)
// exactly where 2 (b - a) x > h_b - h_a. The scan is Felzenszwalb & Huttenlocher's ("Distance
// transforms of sampled functions", 2012): the stack keeps the parabolas of the real lower
// envelope in order, and the top p (above a) is popped for a new site u when p's stretch closes
// before it opens, X(p, u) <= X(a, p) — compared here cross-multiplied in 64-bit integers,
// (h_u - h_p)(p - a) <= (h_p - h_a)(u - p), where Meijster's scan above divides once per pushed
// site (a quarter of its time on the profile). The write-back walks x forward and moves to the
// next parabola only while it is strictly lower there, with the same comparison.
// Ties: at an integer x where several parabolas tie for the minimum, the walk stops at the first
// (smallest index) of the stack's; a popped parabola ties with the minimum only where the one
// below it (a smaller index) ties too, so the smallest minimising index wins, as in envelope_1d.
// h (< 2^30: f < kInf < 2^29 and u^2 < 2^29) is kept in `t`.
inline void envelope_euclidean_int32(int n, const std::int32_t* f, std::int32_t* out,
                                     std::int32_t* arg, std::int32_t* s, std::int32_t* h) {
  int q = -1;
  for (int u = 0; u < n; ++u) {
    const std::int32_t fu = f[u];
    if (!(fu < EuclideanInt32::kInf)) continue;
    const std::int64_t hu = std::int64_t{u} * u + fu;
    while (q >= 1) {
      const std::int64_t a = s[q - 1], ha = h[q - 1], p = s[q], hp = h[q];
      if ((hu - hp) * (p - a) > (hp - ha) * (u - p)) break;
      --q;
    }
    ++q;
    s[q] = u;
    h[q] = static_cast<std::int32_t>(hu);
  }
  if (q < 0) {
    std::fill(out, out + n, EuclideanInt32::kInf);
    if (arg) std::fill(arg, arg + n, -1);
    return;
  }
  int k = 0;
  for (int x = 0; x < n; ++x) {
    while (k < q && 2 * std::int64_t{s[k + 1] - s[k]} * x > std::int64_t{h[k + 1]} - h[k]) ++k;
    const std::int32_t site = s[k], d = x - site;
    out[x] = d * d + f[site];
    if (arg) arg[x] = site;
  }
}

// Manhattan: forward and backward min-plus sweeps. kInf saturates.
inline constexpr std::int32_t kManhattanInf = std::numeric_limits<std::int32_t>::max() / 4;

inline void manhattan_1d(int n, const std::int32_t* f, std::int32_t* out, std::int32_t* arg) {
  std::int32_t best = kManhattanInf, site = -1;
  for (int x = 0; x < n; ++x) {
    const std::int32_t from_left = site >= 0 ? best + 1 : kManhattanInf;
    if (f[x] < from_left) {  // own site only when strictly better: ties stay with the left
      best = f[x];
      site = f[x] < kManhattanInf ? x : -1;
    } else {
      best = from_left;
    }
    out[x] = best;
    arg[x] = site;
  }
  for (int x = n - 2; x >= 0; --x) {
    if (arg[x + 1] < 0) continue;
    const std::int32_t from_right = out[x + 1] + 1;
    if (from_right < out[x]) {  // strictly: ties keep the smaller index
      out[x] = from_right;
      arg[x] = arg[x + 1];
    }
  }
}

}  // namespace voxfield::detail
