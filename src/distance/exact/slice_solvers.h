// voxfield — passes B and C of the exact transform: the 2-D solve of one z-slice after pass A
// (internal). A slice needs only its own g values, so each one is solved alone, in thread-local
// buffers, by one of three solvers chosen from the plan:
//  - the lower envelope (Meijster, Roerdink & Hesselink, "A general algorithm for computing
//    distance transforms in linear time", 2000) for Chebyshev and Euclidean: along x on rows,
//    transposed, along y on rows, transposed back (line kernels in ../line_transforms.h; for
//    unit-spacing Euclidean costs in 32 bits, its division-free form);
//  - two min-plus sweeps per axis for Manhattan (Rosenfeld & Pfaltz 1966), the pass along y on
//    whole rows at once;
//  - truncated min-convolutions (Felzenszwalb & Huttenlocher 2012, ../truncated_min_convolution.h)
//    for small clamps of unit-spacing Euclidean fields without nearest sites.
// Shared by the whole-field and the local drivers: both solve their slices with the same code.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <type_traits>

#include "../envelope_lanes.h"
#include "../field_plan.h"
#include "../line_transforms.h"
#include "../truncated_min_convolution.h"
#include "../window_lanes.h"
#include "voxfield/detail/vector_clones.h"

namespace voxfield::detail::exact {

using Plan = FieldPlan;

// The clamp as a cost of the plan's kernel: squared for Euclidean (whose passes minimise squared
// distances, so that no square root is taken per voxel), the distance itself otherwise.
inline double clamp_cost(const Plan& p) {
  return p.metric == Metric::kEuclidean ? p.clamp * p.clamp : p.clamp;
}

// Per-thread buffers for one slice. Results (h, arg_x, arg_y) end up row-major: index y*X + x.
// Arrays are left uninitialised: every element is written before it is read.
template <class A>
struct Scratch {
  std::unique_ptr<A[]> p;
  std::size_t capacity = 0;
  void resize(std::size_t n) {  // contents are not kept; the storage is, when large enough
    if (n <= capacity) return;
    p.reset(new A[n]);
    capacity = n;
  }
  A* data() { return p.get(); }
  const A* data() const { return p.get(); }
  A& operator[](std::size_t i) { return p[i]; }
  const A& operator[](std::size_t i) const { return p[i]; }
};

// Lines solved side by side by kernels that have a lock-step form (envelope_lanes.h).
inline constexpr int kEnvelopeLanes = 4;

template <class V>
struct SliceBuffers {
  Scratch<V> f, h, tmp;
  Scratch<std::int32_t> arg_x, arg_y, targ, s, t;
  Scratch<std::int32_t> lane_in, lane_out;  // lines copied out of a windowed pass for the envelope
  void resize(int X, int Y) {
    const std::size_t n = static_cast<std::size_t>(X) * Y;
    f.resize(n);
    h.resize(n);
    tmp.resize(n);
    arg_x.resize(n);
    arg_y.resize(n);
    targ.resize(n);
    // The envelope's stacks: room for the lock-step kernel's lanes (solve_lines).
    const std::size_t stack = kEnvelopeLanes * envelope_lane_stride(std::max(X, Y));
    s.resize(stack);
    t.resize(stack);
    if constexpr (std::is_same_v<V, std::int32_t>) {  // the windowed passes' costs only
      lane_in.resize(kWindowLanes * static_cast<std::size_t>(std::max(X, Y)));
      lane_out.resize(kWindowLanes * static_cast<std::size_t>(std::max(X, Y)));
    }
  }
};

// Blocked transpose of the columns x_lo..x_hi-1 of an X-by-Y row-major array (index y*X + x) into
// column-major order (index x*Y + y), and back.
template <class A>
void to_columns(const A* in, A* out, int X, int Y, int x_lo, int x_hi) {
  constexpr int kBlock = 32;
  for (int y0 = 0; y0 < Y; y0 += kBlock)
    for (int x0 = x_lo; x0 < x_hi; x0 += kBlock)
      for (int y = y0; y < std::min(Y, y0 + kBlock); ++y)
        for (int x = x0; x < std::min(x_hi, x0 + kBlock); ++x)
          out[static_cast<std::size_t>(x) * Y + y] = in[static_cast<std::size_t>(y) * X + x];
}

template <class A>
void to_rows(const A* in, A* out, int X, int Y, int x_lo, int x_hi) {
  constexpr int kBlock = 32;
  for (int x0 = x_lo; x0 < x_hi; x0 += kBlock)
    for (int y0 = 0; y0 < Y; y0 += kBlock)
      for (int x = x0; x < std::min(x_hi, x0 + kBlock); ++x)
        for (int y = y0; y < std::min(Y, y0 + kBlock); ++y)
          out[static_cast<std::size_t>(y) * X + x] = in[static_cast<std::size_t>(x) * Y + y];
}

// One line through the envelope kernel, with shortcuts for the lines that are common in real
// worlds and need no envelope: all sites (cost 0 everywhere: inside solid matter) and no site at
// all (open air far from everything).
// Returns false, writing nothing, for a line that needs the envelope.
template <class V>
bool solve_line_shortcut(int n, const V* f, V* out, std::int32_t* arg, V inf) {
  bool all_zero = true, all_inf = true;
  for (int i = 0; i < n; ++i) {
    all_zero &= f[i] == V(0);
    all_inf &= !(f[i] < inf);
  }
  if (!all_zero && !all_inf) return false;
  std::fill(out, out + n, all_zero ? V(0) : inf);
  if (arg) {
    for (int i = 0; i < n; ++i) arg[i] = all_zero ? i : -1;
  }
  return true;
}

template <class Kernel, class V>
void solve_line(const Kernel& k, int n, const V* f, V* out, std::int32_t* arg, std::int32_t* s,
                std::int32_t* t, V inf) {
  if (!solve_line_shortcut(n, f, out, arg, inf)) k(n, f, out, arg, s, t);
}

// The unit-spacing Euclidean kernel in 32-bit costs, with its lock-step form for solve_lines.
struct EuclideanInt32Kernel {
  void operator()(int n, const std::int32_t* f, std::int32_t* out, std::int32_t* arg,
                  std::int32_t* s, std::int32_t* t) const {
    envelope_euclidean_int32(n, f, out, arg, s, t);
  }
  void lanes(int n, const std::int32_t* const* f, std::int32_t* const* out,
             std::int32_t* const* arg, std::int32_t* s, std::int32_t* t) const {
    envelope_euclidean_int32_lanes<kEnvelopeLanes>(n, f, out, arg, s, t);
  }
};

// `count` lines of n voxels: line i reads f + i * n and writes out + i * n (and arg + i * n when
// arg is not null). Lines that need the envelope go through the kernel's lock-step form
// kEnvelopeLanes at a time where it has one, the rest one by one.
template <class Kernel, class V>
void solve_lines(const Kernel& k, int count, int n, const V* f, V* out, std::int32_t* arg,
                 std::int32_t* s, std::int32_t* t, V inf) {
  if constexpr (requires(const Kernel& kk, std::int32_t* p) {
                  kk.lanes(0, nullptr, nullptr, nullptr, p, p);
                }) {
    const V* lf[kEnvelopeLanes];
    V* lo[kEnvelopeLanes];
    std::int32_t* la[kEnvelopeLanes];
    int pending = 0;
    for (int i = 0; i < count; ++i) {
      const std::size_t o = static_cast<std::size_t>(i) * n;
      const V* fi = f + o;
      if (solve_line_shortcut(n, fi, out + o, arg ? arg + o : nullptr, inf)) continue;
      lf[pending] = fi;
      lo[pending] = out + o;
      la[pending] = arg ? arg + o : nullptr;
      if (++pending == kEnvelopeLanes) {
        k.lanes(n, lf, lo, arg ? la : nullptr, s, t);
        pending = 0;
      }
    }
    for (int i = 0; i < pending; ++i) k(n, lf[i], lo[i], la[i], s, t);
  } else {
    for (int i = 0; i < count; ++i) {
      const std::size_t o = static_cast<std::size_t>(i) * n;
      solve_line(k, n, f + o, out + o, arg ? arg + o : nullptr, s, t, inf);
    }
  }
}

// 2-D solve of one slice with an envelope kernel (Chebyshev, Euclidean): pass B along x on rows,
// transpose, pass C along y on rows, transpose back.
// Results are needed only for the columns x_lo..x_hi-1 (all of them for whole fields; the output
// window for local updates), so pass C runs on those columns only. `drop_above`: the clamp's cost —
// a pass-B value above it cannot bring any voxel within the clamp (pass C only adds to it), so it
// is dropped as "none", which leaves pass C fewer functions and more lines it skips outright.
template <class KernelX, class KernelY, class V>
void solve_slice_envelope2(const KernelX& kx, const KernelY& ky, int X, int Y, SliceBuffers<V>& b,
                           bool track_sites, V inf, int x_lo, int x_hi, V drop_above) {
  std::int32_t* arg_x = track_sites ? b.arg_x.data() : nullptr;
  std::int32_t* targ = track_sites ? b.targ.data() : nullptr;
  solve_lines(kx, Y, X, b.f.data(), b.h.data(), arg_x, b.s.data(), b.t.data(), inf);
  if (drop_above < inf) {
    V* h = b.h.data();
    for (std::size_t i = 0; i < static_cast<std::size_t>(X) * Y; ++i)
      h[i] = h[i] > drop_above ? inf : h[i];
  }
  to_columns(b.h.data(), b.tmp.data(), X, Y, x_lo, x_hi);
  const std::size_t o = static_cast<std::size_t>(x_lo) * Y;
  solve_lines(ky, x_hi - x_lo, Y, b.tmp.data() + o, b.f.data() + o, targ ? targ + o : nullptr,
              b.s.data(), b.t.data(), inf);
  to_rows(b.f.data(), b.h.data(), X, Y, x_lo, x_hi);
  if (track_sites) to_rows(b.targ.data(), b.arg_y.data(), X, Y, x_lo, x_hi);
}

// Average window steps per voxel above which a group of lines goes to the envelope instead
// (window_lanes.h). A step is an add and a min over kWindowLanes lanes. Measured on one thread
// (voxfield-bench-field, spheres and terrain at 256³, and voxfield.ndimage on the MRI volume and
// the random one; the machine's noise about ±10 %): 24 steps gave 470–510 / 290–330 / 517 / 316
// ms, 96 gave 295–355 / 237–280 / 445–450 / 283–330, no limit at all 372–381 / 308–313 / 457 /
// 300–350, and the envelope alone 339 / 305 ms on the first two.
inline constexpr std::int64_t kWindowStepsPerVoxel = 96;

// 2-D solve of a whole slice of unit-spacing Euclidean costs, values only, by windowed min-plus
// (window_lanes.h): along y on the row-major slice (its lanes the columns), transposed, along x
// (its lanes the rows), transposed back. The passes' order does not change the values (the sum
// of squares is separable); the clamp's drop applies after the first, as in the envelope's.
inline void solve_slice_windowed(const EuclideanInt32Kernel& k, int X, int Y,
                                 SliceBuffers<std::int32_t>& b, std::int32_t drop_above) {
  constexpr std::int32_t kInf = EuclideanInt32::kInf;
  const auto envelope = [&](int lines, int n, const std::int32_t* in, std::int32_t* out) {
    solve_lines(k, lines, n, in, out, nullptr, b.s.data(), b.t.data(), kInf);
  };
  window_lines_or_envelope(X, Y, b.f.data(), static_cast<std::size_t>(X), b.h.data(),
                           kWindowStepsPerVoxel, b.lane_in.data(), b.lane_out.data(), envelope);
  if (drop_above < kInf) {
    std::int32_t* h = b.h.data();
    for (std::size_t i = 0; i < static_cast<std::size_t>(X) * Y; ++i)
      h[i] = h[i] > drop_above ? kInf : h[i];
  }
  to_columns(b.h.data(), b.tmp.data(), X, Y, 0, X);
  window_lines_or_envelope(Y, X, b.tmp.data(), static_cast<std::size_t>(Y), b.f.data(),
                           kWindowStepsPerVoxel, b.lane_in.data(), b.lane_out.data(), envelope);
  to_rows(b.f.data(), b.h.data(), X, Y, 0, X);
}

template <class Kernel, class V>
void solve_slice_envelope(const Kernel& kx, const Kernel& ky, int X, int Y, SliceBuffers<V>& b,
                          bool track_sites, V inf, int x_lo, int x_hi, V drop_above) {
  if constexpr (std::is_same_v<Kernel, EuclideanInt32Kernel>) {
    if (!track_sites && x_lo == 0 && x_hi == X) {
      solve_slice_windowed(kx, X, Y, b, drop_above);
      return;
    }
  }
  solve_slice_envelope2(kx, ky, X, Y, b, track_sites, inf, x_lo, x_hi, drop_above);
}

// 2-D solve of one slice for Manhattan: min-plus sweeps along x per row, then along y across whole
// rows at once (contiguous, vectorisable). Ties keep the smaller index, as the envelope does.
// (Twice: in AVX2 too, vector_clones.h: the y sweeps are whole rows of integer lanes.)
VOXFIELD_AVX2_CLONE inline void solve_slice_manhattan(int X, int Y, SliceBuffers<std::int32_t>& b,
                                                      bool track_sites, int x_lo, int x_hi) {
  constexpr std::int32_t kInf = kManhattanInf;
  std::int32_t* h = b.h.data();
  if (track_sites) {
    for (int y = 0; y < Y; ++y) {
      const std::size_t o = static_cast<std::size_t>(y) * X;
      manhattan_1d(X, b.f.data() + o, h + o, b.arg_x.data() + o);
    }
  } else {
    // Each row's sweep is one long dependency chain; sweeping kRows rows together lets their
    // chains overlap in the pipeline.
    constexpr int kRows = 4;
    int y = 0;
    for (; y + kRows <= Y; y += kRows) {
      const std::int32_t* f[kRows];
      std::int32_t* r[kRows];
      std::int32_t best[kRows];
      for (int k = 0; k < kRows; ++k) {
        f[k] = b.f.data() + static_cast<std::size_t>(y + k) * X;
        r[k] = h + static_cast<std::size_t>(y + k) * X;
        best[k] = kInf;
      }
      for (int x = 0; x < X; ++x)
        for (int k = 0; k < kRows; ++k)
          r[k][x] = best[k] = std::min(f[k][x], std::min(best[k] + 1, kInf));
      for (int x = X - 2; x >= 0; --x)
        for (int k = 0; k < kRows; ++k) r[k][x] = std::min(r[k][x], r[k][x + 1] + 1);
    }
    for (; y < Y; ++y) {
      const std::size_t o = static_cast<std::size_t>(y) * X;
      const std::int32_t* f = b.f.data() + o;
      std::int32_t* r = h + o;
      std::int32_t best = kInf;
      for (int x = 0; x < X; ++x) r[x] = best = std::min(f[x], std::min(best + 1, kInf));
      for (int x = X - 2; x >= 0; --x) r[x] = std::min(r[x], r[x + 1] + 1);
    }
  }
  std::int32_t* ay = b.arg_y.data();
  if (track_sites) {
    for (int y = 0; y < Y; ++y)
      for (int x = x_lo; x < x_hi; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * X + x;
        ay[i] = h[i] < kInf ? y : -1;
      }
  }
  for (int y = 1; y < Y; ++y) {
    std::int32_t* r = h + static_cast<std::size_t>(y) * X;
    const std::int32_t* prev = r - X;
    if (track_sites) {
      std::int32_t* a = ay + static_cast<std::size_t>(y) * X;
      const std::int32_t* pa = a - X;
      for (int x = x_lo; x < x_hi; ++x) {
        if (pa[x] >= 0 && prev[x] + 1 <= r[x]) {
          r[x] = prev[x] + 1;
          a[x] = pa[x];
        }
      }
    } else {
      for (int x = x_lo; x < x_hi; ++x) r[x] = std::min(r[x], std::min(prev[x] + 1, kInf));
    }
  }
  for (int y = Y - 2; y >= 0; --y) {
    std::int32_t* r = h + static_cast<std::size_t>(y) * X;
    const std::int32_t* next = r + X;
    if (track_sites) {
      std::int32_t* a = ay + static_cast<std::size_t>(y) * X;
      const std::int32_t* na = a + X;
      for (int x = x_lo; x < x_hi; ++x) {
        if (na[x] >= 0 && next[x] + 1 < r[x]) {
          r[x] = next[x] + 1;
          a[x] = na[x];
        }
      }
    } else {
      for (int x = x_lo; x < x_hi; ++x) r[x] = std::min(r[x], std::min(next[x] + 1, kInf));
    }
  }
}

// Whether the 2-D passes of a clamped unit-spacing Euclidean field without nearest sites are
// truncated min-convolutions (truncated_min_convolution.h): 16-bit costs hold clamps below
// kMaxReach + 1. On whole slices they cost 2D + 1 vector steps per 8 voxels and pass where the
// envelope's scans cost about the same at any clamp, yet they stayed ahead up to the largest
// clamp: 256³ terrain / spheres on 2 threads, clamp 16: 141 → 58 / 110 → 57 ms, clamp 64:
// 174 → 124 / 178 → 130 ms.
inline bool truncated_passes(const Plan& p, bool sites) {
  return p.metric == Metric::kEuclidean && p.unit_spacing && !sites && std::isfinite(p.clamp) &&
         p.clamp >= 1 && p.clamp < TruncatedMinConvolution::kMaxReach + 1;
}

// Calls fn(value_tag, solve, inf) with the 2-D slice solver of the plan's metric: V (the type of
// value_tag) is the cost type the passes minimise, solve(X, Y, SliceBuffers<V>&, x_lo, x_hi) solves
// one slice for the columns x_lo..x_hi-1,
// inf is V's "no site". `extent` decides whether 32-bit Euclidean costs are wide enough.
template <class Fn>
void dispatch_solver(const Plan& p, Vec3i extent, Fn&& fn) {
  const bool sites = p.sites;
  // The clamp as a cost of each kernel (squared for Euclidean), rounded down where costs are
  // integers: pass-B values above it are dropped (solve_slice_envelope2).
  const double clamp = clamp_cost(p);
  auto drop = [clamp](auto inf) {
    using V = decltype(inf);
    if (!(clamp < static_cast<double>(inf))) return inf;
    if constexpr (std::is_integral_v<V>) return static_cast<V>(std::floor(clamp));
    return static_cast<V>(clamp);
  };
  if (p.metric == Metric::kManhattan) {
    auto solve = [sites](int X, int Y, SliceBuffers<std::int32_t>& b, int lo, int hi) {
      solve_slice_manhattan(X, Y, b, sites, lo, hi);
    };
    fn(std::int32_t{}, solve, kManhattanInf);
  } else if (p.metric == Metric::kChebyshev) {
    auto k = [](int n, const std::int32_t* f, std::int32_t* o, std::int32_t* a, std::int32_t* s,
                std::int32_t* t) { envelope_1d(Chebyshev{}, n, f, o, a, s, t); };
    auto solve = [k, sites, d = drop(Chebyshev::kInf)](int X, int Y, SliceBuffers<std::int32_t>& b,
                                                       int lo, int hi) {
      solve_slice_envelope(k, k, X, Y, b, sites, Chebyshev::kInf, lo, hi, d);
    };
    fn(std::int32_t{}, solve, Chebyshev::kInf);
  } else if (p.unit_spacing && static_cast<double>(extent.x) * extent.x +
                                       static_cast<double>(extent.y) * extent.y +
                                       static_cast<double>(extent.z) * extent.z <
                                   (1 << 29)) {
    const EuclideanInt32Kernel k;
    auto solve = [k, sites, d = drop(EuclideanInt32::kInf)](
                     int X, int Y, SliceBuffers<std::int32_t>& b, int lo, int hi) {
      solve_slice_envelope(k, k, X, Y, b, sites, EuclideanInt32::kInf, lo, hi, d);
    };
    fn(std::int32_t{}, solve, EuclideanInt32::kInf);
  } else if (p.unit_spacing) {
    auto k = [](int n, const std::int64_t* f, std::int64_t* o, std::int32_t* a, std::int32_t* s,
                std::int32_t* t) { envelope_1d(EuclideanInt{}, n, f, o, a, s, t); };
    auto solve = [k, sites, d = drop(EuclideanInt::kInf)](
                     int X, int Y, SliceBuffers<std::int64_t>& b, int lo, int hi) {
      solve_slice_envelope(k, k, X, Y, b, sites, EuclideanInt::kInf, lo, hi, d);
    };
    fn(std::int64_t{}, solve, EuclideanInt::kInf);
  } else {
    const EuclideanReal ex{p.spacing[0] * p.spacing[0]}, ey{p.spacing[1] * p.spacing[1]};
    auto kx = [ex](int n, const double* f, double* o, std::int32_t* a, std::int32_t* s,
                   std::int32_t* t) { envelope_1d(ex, n, f, o, a, s, t); };
    auto ky = [ey](int n, const double* f, double* o, std::int32_t* a, std::int32_t* s,
                   std::int32_t* t) { envelope_1d(ey, n, f, o, a, s, t); };
    auto solve = [kx, ky, sites, d = drop(EuclideanReal::kInf)](
                     int X, int Y, SliceBuffers<double>& b, int lo, int hi) {
      // The two axes weigh differently; the slice solver takes one kernel per axis.
      solve_slice_envelope2(kx, ky, X, Y, b, sites, EuclideanReal::kInf, lo, hi, d);
    };
    fn(double{}, solve, EuclideanReal::kInf);
  }
}

}  // namespace voxfield::detail::exact
