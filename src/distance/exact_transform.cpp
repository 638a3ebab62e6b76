// voxfield — exact distance transforms (Manhattan, Chebyshev, Euclidean; signed; clamped; nearest
// sites) by separable passes.
//
// Meijster, Roerdink & Hesselink, "A general algorithm for computing distance transforms in linear
// time" (2000), with the line kernels in line_transforms.h. The passes run in this order:
//
//  A. along z, per column: g(x,y,z) = distance in voxels to the nearest site in the column
//     (x, y, *). Runs on rows of chunk-edge voxels along x at once (vectorisable), and stores g in
//     the output chunks themselves, so no volume-sized scratch is needed (peak memory beyond input
//     and output is a few slices).
//  B. along x and C. along y, per z-slice: a slice only needs its own g values, so each slice is
//     gathered into thread-local buffers, solved in 2-D, and written back in place as final values.
//
// Signed fields need two transforms (to solid and to air) but only one stored g per voxel: a
// solid voxel's distance to the nearest solid is 0 and an air voxel's distance to the nearest air
// is 0, so each voxel stores the one that is not trivially zero.
//
// With a clamp D, a g whose contribution alone exceeds D is dropped as "none": any site reached
// through it is farther than D, so the clamped result is unchanged. This also lets integer
// storage hold g in place when the clamp (explicit, or implied by the type's range) fits.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <type_traits>

#include "field_plan.h"
#include "line_transforms.h"
#include "truncated_min_convolution.h"
#include "voxfield/distance.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield {
namespace {

using detail::Chebyshev;
using detail::EuclideanInt;
using detail::EuclideanReal;
using detail::TruncatedMinConvolution;

// Chunk arrays covering a chunk-aligned box, addressed by voxel.
template <class T>
struct ChunkedVolume {
  Box3i box;  // chunk-aligned
  int edge = 0, shift = 0;
  Vec3i nchunks;
  std::vector<Vec3i> coords;
  std::vector<std::unique_ptr<T[]>> chunks;

  ChunkedVolume(const Box3i& aligned, int chunk_edge) : box(aligned), edge(chunk_edge) {
    shift = std::countr_zero(static_cast<unsigned>(chunk_edge));
    nchunks = {box.size().x >> shift, box.size().y >> shift, box.size().z >> shift};
    const Vec3i c0{box.begin.x >> shift, box.begin.y >> shift, box.begin.z >> shift};
    const std::size_t n = static_cast<std::size_t>(nchunks.x) * nchunks.y * nchunks.z;
    coords.reserve(n);
    chunks.resize(n);
    for (int z = 0; z < nchunks.z; ++z)
      for (int y = 0; y < nchunks.y; ++y)
        for (int x = 0; x < nchunks.x; ++x) coords.push_back(c0 + Vec3i{x, y, z});
    const std::size_t volume = std::size_t{1} << (3 * shift);
    for (auto& c : chunks) c.reset(new T[volume]);
  }
  // Pointer to the `edge` voxels of the row (chunk column cx, y, z), x fastest.
  T* row(int cx, int y, int z) {
    const int ly = y - box.begin.y, lz = z - box.begin.z;
    const std::size_t ci = (static_cast<std::size_t>(lz >> shift) * nchunks.y + (ly >> shift)) * nchunks.x + cx;
    const int mask = edge - 1;
    return chunks[ci].get() + (static_cast<std::size_t>(lz & mask) << (2 * shift)) +
           (static_cast<std::size_t>(ly & mask) << shift);
  }
};

// Rows of the world's chunks as 0/1 solid flags, for the same chunk-aligned box.
class SolidRows {
 public:
  SolidRows(const Grid<std::uint8_t>& g, const Box3i& aligned) : box_(aligned) {
    edge_ = g.chunk_edge();
    shift_ = g.chunk_shift();
    nchunks_ = {box_.size().x >> shift_, box_.size().y >> shift_, box_.size().z >> shift_};
    const Vec3i c0{box_.begin.x >> shift_, box_.begin.y >> shift_, box_.begin.z >> shift_};
    std::fill(std::begin(zeros_), std::end(zeros_), 0);
    std::fill(std::begin(ones_), std::end(ones_), 1);
    for (int z = 0; z < nchunks_.z; ++z)
      for (int y = 0; y < nchunks_.y; ++y)
        for (int x = 0; x < nchunks_.x; ++x) {
          const ChunkView<std::uint8_t> v = g.chunk_view(c0 + Vec3i{x, y, z});
          chunks_.push_back(v.voxels ? v.voxels : (v.uniform_value ? ones_ : zeros_));
          dense_.push_back(v.voxels != nullptr);
        }
  }
  // Material row (dense chunks) or a row of 0/1 (uniform chunks): non-zero means solid.
  const std::uint8_t* row(int cx, int y, int z) const {
    const int ly = y - box_.begin.y, lz = z - box_.begin.z;
    const std::size_t ci = (static_cast<std::size_t>(lz >> shift_) * nchunks_.y + (ly >> shift_)) * nchunks_.x + cx;
    if (!dense_[ci]) return chunks_[ci];
    const int mask = edge_ - 1;
    return chunks_[ci] + (static_cast<std::size_t>(lz & mask) << (2 * shift_)) +
           (static_cast<std::size_t>(ly & mask) << shift_);
  }
 private:
  Box3i box_;
  int edge_, shift_;
  Vec3i nchunks_;
  std::vector<const std::uint8_t*> chunks_;
  std::vector<char> dense_;
  std::uint8_t zeros_[128], ones_[128];
};

using Plan = detail::FieldPlan;

// One step of a z sweep over `n` lanes: ds / da are the running distances (in voxels) to the
// nearest solid / air voxel seen so far, saturating at cap; returns through `c` the one each voxel
// stores (for signed fields the distance that is not trivially zero). Shared by the whole-field
// and the local passes.
// G: the lane type (32 bits in general; 8 bits when cap fits, for four times the lanes per step).
template <bool kSigned, class G = std::uint32_t>
inline void z_sweep_step(const std::uint8_t* __restrict w, G* __restrict ds, G* __restrict da, G* __restrict c, std::size_t n,
                         G cap) {
  for (std::size_t i = 0; i < n; ++i) {
    const bool solid = w[i] != 0;
    ds[i] = solid ? G{0} : std::min(static_cast<G>(ds[i] + 1u), cap);
    if constexpr (kSigned) {
      da[i] = solid ? std::min(static_cast<G>(da[i] + 1u), cap) : G{0};
      c[i] = solid ? da[i] : ds[i];
    } else {
      c[i] = ds[i];
    }
  }
}

// Pass A on one chunk column (cx, cy) of the domain: for rows y in the domain, sweep z up and down
// over `edge` lanes along x at once. The column of a row (Z x edge values) lives in `col`, a
// thread-local buffer small enough for the cache, so each output voxel is written exactly once.
// U: the unsigned integer the output storage holds g in; g >= cap is stored as kInf ("none").
template <class U, bool kSigned>
void pass_z(const Plan& p, const SolidRows& world, ChunkedVolume<U>& g, ChunkedVolume<SiteOffset>* sites,
            int cx, int cy, std::uint32_t cap, std::vector<std::uint32_t>& col) {
  constexpr U kInf = std::numeric_limits<U>::max();
  const int e = g.edge;
  const int y0 = std::max(p.domain.begin.y, g.box.begin.y + cy * e);
  const int y1 = std::min(p.domain.end.y, g.box.begin.y + (cy + 1) * e);
  const int z0 = p.domain.begin.z, z1 = p.domain.end.z;
  col.resize(static_cast<std::size_t>(z1 - z0) * e);
  std::uint32_t ds[128], da[128];
  std::int32_t ls[128], la[128];  // z of the last solid / air site seen (sites only)
  for (int y = y0; y < y1; ++y) {
    // Forward (increasing z): distance to the nearest site at or below.
    std::fill(ds, ds + e, cap);
    std::fill(da, da + e, cap);
    // __restrict: the rows never alias, and saying so lets the compiler vectorise the lanes.
    std::uint32_t* __restrict dsr = ds;
    std::uint32_t* __restrict dar = da;
    for (int z = z0; z < z1; ++z) {
      z_sweep_step<kSigned>(world.row(cx, y, z), dsr, dar, col.data() + static_cast<std::size_t>(z - z0) * e,
                            static_cast<std::size_t>(e), cap);
    }
    // Backward (decreasing z): keep the smaller, and store once.
    std::fill(ds, ds + e, cap);
    std::fill(da, da + e, cap);
    for (int z = z1 - 1; z >= z0; --z) {
      const std::uint8_t* __restrict w = world.row(cx, y, z);
      const std::uint32_t* __restrict c = col.data() + static_cast<std::size_t>(z - z0) * e;
      U* __restrict out = g.row(cx, y, z);
      for (int i = 0; i < e; ++i) {
        const bool solid = w[i] != 0;
        dsr[i] = solid ? 0u : std::min(dsr[i] + 1u, cap);
        std::uint32_t v;
        if constexpr (kSigned) {
          dar[i] = solid ? std::min(dar[i] + 1u, cap) : 0u;
          v = std::min(c[i], solid ? dar[i] : dsr[i]);
        } else {
          v = std::min(c[i], dsr[i]);
        }
        out[i] = v >= cap ? kInf : static_cast<U>(v);
      }
    }
    if (!sites) continue;
    // Nearest site along z: below (found by the upward sweep) wins ties.
    std::fill(ls, ls + e, INT32_MIN / 2);
    std::fill(la, la + e, INT32_MIN / 2);
    for (int z = z0; z < z1; ++z) {
      const std::uint8_t* w = world.row(cx, y, z);
      SiteOffset* so = sites->row(cx, y, z);
      for (int i = 0; i < e; ++i) {
        const bool solid = w[i] != 0;
        if (solid) ls[i] = z; else la[i] = z;
        so[i].dz = static_cast<std::int16_t>(std::clamp((kSigned && solid ? la[i] : ls[i]) - z, -32768, 32767));
      }
    }
    std::fill(ls, ls + e, INT32_MAX / 2);
    std::fill(la, la + e, INT32_MAX / 2);
    for (int z = z1 - 1; z >= z0; --z) {
      const std::uint8_t* w = world.row(cx, y, z);
      SiteOffset* so = sites->row(cx, y, z);
      for (int i = 0; i < e; ++i) {
        const bool solid = w[i] != 0;
        if (solid) ls[i] = z; else la[i] = z;
        const std::int32_t above = (kSigned && solid ? la[i] : ls[i]) - z;  // >= 0
        const std::int32_t below = -static_cast<std::int32_t>(so[i].dz);    // >= 0 when found
        if (above < below) so[i].dz = static_cast<std::int16_t>(std::min(above, 32767));
      }
    }
  }
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

template <class V>
struct SliceBuffers {
  Scratch<V> f, h, tmp;
  Scratch<std::int32_t> arg_x, arg_y, targ, s, t;
  void resize(int X, int Y) {
    const std::size_t n = static_cast<std::size_t>(X) * Y;
    f.resize(n);
    h.resize(n);
    tmp.resize(n);
    arg_x.resize(n);
    arg_y.resize(n);
    targ.resize(n);
    s.resize(static_cast<std::size_t>(std::max(X, Y)));
    t.resize(static_cast<std::size_t>(std::max(X, Y)));
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

// 2-D solve of one slice with an envelope kernel (Chebyshev, Euclidean): pass B along x on rows,
// transpose, pass C along y on rows, transpose back.
// One line through the envelope kernel, with shortcuts for the lines that are common in real
// worlds and need no envelope: all sites (cost 0 everywhere: inside solid matter) and no site at
// all (open air far from everything).
template <class Kernel, class V>
void solve_line(const Kernel& k, int n, const V* f, V* out, std::int32_t* arg, std::int32_t* s, std::int32_t* t, V inf) {
  bool all_zero = true, all_inf = true;
  for (int i = 0; i < n; ++i) {
    all_zero &= f[i] == V(0);
    all_inf &= !(f[i] < inf);
  }
  if (all_zero || all_inf) {
    std::fill(out, out + n, all_zero ? V(0) : inf);
    if (arg) {
      for (int i = 0; i < n; ++i) arg[i] = all_zero ? i : -1;
    }
    return;
  }
  k(n, f, out, arg, s, t);
}

// Results are needed only for the columns x_lo..x_hi-1 (all of them for whole fields; the output
// window for local updates), so pass C runs on those columns only. `drop_above`: the clamp's cost —
// a pass-B value above it cannot bring any voxel within the clamp (pass C only adds to it), so it
// is dropped as "none", which leaves pass C fewer functions and more lines it skips outright.
template <class KernelX, class KernelY, class V>
void solve_slice_envelope2(const KernelX& kx, const KernelY& ky, int X, int Y, SliceBuffers<V>& b, bool track_sites,
                           V inf, int x_lo, int x_hi, V drop_above) {
  std::int32_t* arg_x = track_sites ? b.arg_x.data() : nullptr;
  std::int32_t* targ = track_sites ? b.targ.data() : nullptr;
  for (int y = 0; y < Y; ++y) {
    const std::size_t o = static_cast<std::size_t>(y) * X;
    solve_line(kx, X, b.f.data() + o, b.h.data() + o, arg_x ? arg_x + o : nullptr, b.s.data(), b.t.data(), inf);
  }
  if (drop_above < inf) {
    V* h = b.h.data();
    for (std::size_t i = 0; i < static_cast<std::size_t>(X) * Y; ++i) h[i] = h[i] > drop_above ? inf : h[i];
  }
  to_columns(b.h.data(), b.tmp.data(), X, Y, x_lo, x_hi);
  for (int x = x_lo; x < x_hi; ++x) {
    const std::size_t o = static_cast<std::size_t>(x) * Y;
    solve_line(ky, Y, b.tmp.data() + o, b.f.data() + o, targ ? targ + o : nullptr, b.s.data(), b.t.data(), inf);
  }
  to_rows(b.f.data(), b.h.data(), X, Y, x_lo, x_hi);
  if (track_sites) to_rows(b.targ.data(), b.arg_y.data(), X, Y, x_lo, x_hi);
}

template <class Kernel, class V>
void solve_slice_envelope(const Kernel& kx, const Kernel& ky, int X, int Y, SliceBuffers<V>& b, bool track_sites, V inf,
                          int x_lo, int x_hi, V drop_above) {
  solve_slice_envelope2(kx, ky, X, Y, b, track_sites, inf, x_lo, x_hi, drop_above);
}

// 2-D solve of one slice for Manhattan: min-plus sweeps along x per row, then along y across whole
// rows at once (contiguous, vectorisable). Ties keep the smaller index, as the envelope does.
inline void solve_slice_manhattan(int X, int Y, SliceBuffers<std::int32_t>& b, bool track_sites, int x_lo, int x_hi) {
  constexpr std::int32_t kInf = detail::kManhattanInf;
  std::int32_t* h = b.h.data();
  if (track_sites) {
    for (int y = 0; y < Y; ++y) {
      const std::size_t o = static_cast<std::size_t>(y) * X;
      detail::manhattan_1d(X, b.f.data() + o, h + o, b.arg_x.data() + o);
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
        for (int k = 0; k < kRows; ++k) r[k][x] = best[k] = std::min(f[k][x], std::min(best[k] + 1, kInf));
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

// Integer square root: floor(sqrt(n)) exactly.
std::uint64_t isqrt(std::uint64_t n) {
  std::uint64_t r = static_cast<std::uint64_t>(std::sqrt(static_cast<double>(n)));
  while (r > 0 && r * r > n) --r;
  while ((r + 1) * (r + 1) <= n) ++r;
  return r;
}

// Turns the costs the passes minimised into stored values of type T, everything derived from the
// plan. The rounding rule itself lives in detail::encode_distance; only the exact integer square
// root for unit-spacing Euclidean integer storage is added here.
template <class T>
struct Encoder {
  explicit Encoder(const Plan& plan)
      : p(plan),
        none(detail::encode_distance<T>(std::numeric_limits<double>::infinity(), plan)),
        clamp_f(static_cast<float>(std::min(plan.clamp, 3.0e38))),
        // The stored value is a plain function of the cost for unsigned fields in f32 or with an
        // integer metric (scale 1, bias 0): those rows take encode_row().
        row_path(!plan.is_signed && (std::is_same_v<T, float> || plan.metric != Metric::kEuclidean)) {}

  const Plan& p;
  T none;        // stored value for "no site within reach"
  float clamp_f;
  bool row_path;

  // `cost` is what the passes minimised (squared for Euclidean); `inside`: a solid voxel of a
  // signed field (negated).
  T encode(double cost, bool has_site, bool inside) const {
    if (!has_site) return detail::encode_distance<T>(inside ? -std::numeric_limits<double>::infinity()
                                                            : std::numeric_limits<double>::infinity(), p);
    const double d = p.metric == Metric::kEuclidean ? std::sqrt(cost) : cost;
    if constexpr (!std::is_same_v<T, float>) {
      if (p.metric == Metric::kEuclidean && p.unit_spacing && d < p.clamp &&
          p.encoding.scale == std::floor(p.encoding.scale)) {
        // floor(sqrt(cost) * S) computed exactly in integers (cost is an integer here).
        constexpr double kMax = static_cast<double>(std::numeric_limits<T>::max());
        const std::uint64_t n = static_cast<std::uint64_t>(cost) * static_cast<std::uint64_t>(p.encoding.scale * p.encoding.scale);
        const std::uint64_t r = isqrt(n);
        const double scaled = inside ? -static_cast<double>(r + (r * r != n ? 1 : 0)) : static_cast<double>(r);
        return static_cast<T>(std::clamp(scaled + static_cast<double>(p.encoding.bias), 0.0, kMax));
      }
    }
    return detail::encode_distance<T>(inside ? -d : d, p);
  }

  // Branch-light encoding of a row when row_path holds: the same values as encode().
  template <class V>
  void encode_row(const V* cost, T* out, int count, V inf, V clamp_v) const {
    const bool euclid = p.metric == Metric::kEuclidean;
    for (int i = 0; i < count; ++i) {
      const V c = cost[i];
      if (!(c < inf && c <= clamp_v)) {
        out[i] = none;
      } else if constexpr (std::is_same_v<T, float>) {
        out[i] = std::min(euclid ? std::sqrt(static_cast<float>(c)) : static_cast<float>(c), clamp_f);
      } else {
        out[i] = static_cast<T>(std::min<double>(static_cast<double>(c), std::numeric_limits<T>::max()));
      }
    }
  }
};

// Calls fn(cx, local_x0, count, x_offset) for the pieces of the domain row that fall in each chunk
// column: local_x0 is the first voxel within the chunk row, x_offset its index within the domain.
template <class Fn>
void for_each_row_segment(const Plan& p, int edge, int shift, Fn&& fn) {
  const int bx = p.domain.begin.x, ex = p.domain.end.x, ax = p.aligned.begin.x;
  for (int cx = (bx - ax) >> shift; cx <= (ex - 1 - ax) >> shift; ++cx) {
    const int c0 = ax + (cx << shift);
    const int x0 = std::max(bx, c0), x1 = std::min(ex, c0 + edge);
    fn(cx, x0 - c0, x1 - x0, x0 - bx);
  }
}

template <class T, class U, class V, class Solve>
void pass_slices(const Plan& p, const SolidRows& world, ChunkedVolume<U>& g,
                 ChunkedVolume<SiteOffset>* sites, const Solve& solve, const Encoder<T>& encoder,
                 std::uint32_t cap, V inf) {
  constexpr U kInfU = std::numeric_limits<U>::max();
  const int X = p.domain.size().x, Y = p.domain.size().y;
  const int by = p.domain.begin.y;
  const double sz = p.spacing[2];
  const double clamp_cost = p.metric == Metric::kEuclidean ? p.clamp * p.clamp : p.clamp;
  const V clamp_v = clamp_cost >= static_cast<double>(inf) ? inf : static_cast<V>(clamp_cost);
  const bool euclid = p.metric == Metric::kEuclidean;
  const U cap_u = static_cast<U>(std::min<std::uint64_t>(cap, kInfU));
  const int passes = p.is_signed ? 2 : 1;
  // Ranges of several slices each, so that the buffers are allocated a few times per thread only.
  const std::size_t Z = static_cast<std::size_t>(p.domain.size().z);
  const std::size_t grain = std::max<std::size_t>(1, Z / (4 * static_cast<std::size_t>(max_threads())));
  parallel_for(Z, grain, [&](std::size_t zb, std::size_t ze) {
    SliceBuffers<V> buf[2];
    std::vector<std::uint8_t> solid(static_cast<std::size_t>(X) * Y);
    std::vector<std::int16_t> dz(sites ? static_cast<std::size_t>(X) * Y : 0);
    for (int k = 0; k < passes; ++k) buf[k].resize(X, Y);
    for (std::size_t zi = zb; zi < ze; ++zi) {
      const int z = p.domain.begin.z + static_cast<int>(zi);
      // Gather the slice: g -> the cost the 2-D passes minimise.
      for (int y = 0; y < Y; ++y) {
        for_each_row_segment(p, g.edge, g.shift, [&](int cx, int lx, int count, int xo) {
          const U* gs = g.row(cx, by + y, z) + lx;
          const std::uint8_t* ws = world.row(cx, by + y, z) + lx;
          const std::size_t o = static_cast<std::size_t>(y) * X + xo;
          V* f0 = buf[0].f.data() + o;
          for (int i = 0; i < count; ++i) {
            V c;
            if (euclid) {
              const double gz = p.unit_spacing ? static_cast<double>(gs[i]) : sz * gs[i];
              c = gs[i] >= cap_u ? inf : static_cast<V>(gz * gz);
              c = c > clamp_v ? inf : c;
            } else {
              c = gs[i] >= cap_u ? inf : static_cast<V>(gs[i]);
            }
            f0[i] = c;
          }
          if (p.is_signed) {
            V* f1 = buf[1].f.data() + o;
            std::uint8_t* so = solid.data() + o;
            for (int i = 0; i < count; ++i) {
              const bool s = ws[i] != 0;
              so[i] = s;
              f1[i] = s ? f0[i] : V(0);  // distance to air
              f0[i] = s ? V(0) : f0[i];  // distance to solid
            }
          } else if (sites) {
            std::uint8_t* so = solid.data() + o;
            for (int i = 0; i < count; ++i) so[i] = ws[i] != 0;
          }
          if (sites) {
            const SiteOffset* ss = sites->row(cx, by + y, z) + lx;
            for (int i = 0; i < count; ++i) dz[o + i] = ss[i].dz;
          }
        });
      }
      for (int k = 0; k < passes; ++k) solve(X, Y, buf[k], 0, X);
      // Encode and write the final values back into the same slice.
      for (int y = 0; y < Y; ++y) {
        for_each_row_segment(p, g.edge, g.shift, [&](int cx, int lx, int count, int xo) {
          T* out = reinterpret_cast<T*>(g.row(cx, by + y, z)) + lx;  // T and U have the same size
          const std::size_t o = static_cast<std::size_t>(y) * X + xo;
          if (encoder.row_path) {
            encoder.encode_row(buf[0].h.data() + o, out, count, inf, clamp_v);
          } else {
            for (int i = 0; i < count; ++i) {
              const bool inside = p.is_signed && solid[o + i];
              const V cost = buf[inside ? 1 : 0].h[o + i];
              const bool has_site = cost < inf && cost <= clamp_v;
              out[i] = encoder.encode(static_cast<double>(cost), has_site, inside);
            }
          }
          if (!sites) return;
          SiteOffset* so_out = sites->row(cx, by + y, z) + lx;
          for (int i = 0; i < count; ++i) {
            const int x = xo + i;
            const bool inside = p.is_signed && solid[o + i];
            const SliceBuffers<V>& b = buf[inside ? 1 : 0];
            const V cost = b.h[o + i];
            SiteOffset so;
            if (cost < inf && cost <= clamp_v) {
              const std::int32_t ys = b.arg_y[o + i];
              const std::int32_t xs = b.arg_x[static_cast<std::size_t>(ys) * X + x];
              so.dx = static_cast<std::int16_t>(xs - x);
              so.dy = static_cast<std::int16_t>(ys - y);
              // A column voxel that is itself a site of this transform (solid for the distance to
              // solid, air for the distance to air) stored the other transform's dz: its own is 0.
              const std::size_t col = static_cast<std::size_t>(ys) * X + xs;
              const bool column_is_site = p.is_signed ? (solid[col] != 0) != inside : solid[col] != 0;
              so.dz = column_is_site ? std::int16_t{0} : dz[col];
            }
            so_out[i] = so;
          }
        });
      }
    }
  });
}

// Whether the 2-D passes of a clamped unit-spacing Euclidean field without nearest sites are
// truncated min-convolutions (truncated_min_convolution.h): 16-bit costs hold clamps below
// kMaxReach + 1. On whole slices they cost 2D + 1 vector steps per 8 voxels and pass where the
// envelope's scans cost about the same at any clamp, yet they stayed ahead up to the largest
// clamp: 256³ terrain / spheres on 2 threads, clamp 16: 141 → 58 / 110 → 57 ms, clamp 64:
// 174 → 124 / 178 → 130 ms.
bool truncated_passes(const Plan& p, bool sites) {
  return p.metric == Metric::kEuclidean && p.unit_spacing && !sites && std::isfinite(p.clamp) && p.clamp >= 1 &&
         p.clamp < TruncatedMinConvolution::kMaxReach + 1;
}

// One row of a slice into TruncatedMinConvolution's inputs: g (voxels along z, `cap` or more for
// none) becomes its square; signed fields split it into the distance to solid (f0, for air
// voxels) and to air (f1, for solid ones) and note which voxels are solid in `solid`.
template <class G>
void gather_truncated_row(const G* g, const std::uint8_t* world, int count, std::uint32_t cap, bool is_signed,
                          TruncatedMinConvolution::Cost* f0, TruncatedMinConvolution::Cost* f1, std::uint8_t* solid) {
  using Cost = TruncatedMinConvolution::Cost;
  if (!is_signed) {
    for (int i = 0; i < count; ++i) f0[i] = g[i] < cap ? static_cast<Cost>(g[i] * g[i]) : TruncatedMinConvolution::kInf;
    return;
  }
  for (int i = 0; i < count; ++i) {
    const Cost c = g[i] < cap ? static_cast<Cost>(g[i] * g[i]) : TruncatedMinConvolution::kInf;
    const bool s = world[i] != 0;
    if (solid) solid[i] = s;
    f1[i] = s ? c : Cost{0};  // distance to air
    f0[i] = s ? Cost{0} : c;  // distance to solid
  }
}

// Encodes `count` solved costs of row y from column x0 of `conv` (conv[1] for the solid voxels
// of signed fields, `solid` giving them) into `out`.
template <class T>
void encode_truncated_row(const Encoder<T>& encoder, const TruncatedMinConvolution* conv, int y, int x0, int count,
                          const std::uint8_t* solid, T* out, TruncatedMinConvolution::Cost drop) {
  using Conv = TruncatedMinConvolution;
  if (encoder.row_path) {
    encoder.encode_row(conv[0].out_row(y) + x0, out, count, Conv::kInf, drop);
    return;
  }
  for (int i = 0; i < count; ++i) {
    const bool inside = encoder.p.is_signed && solid[i];
    const Conv::Cost cost = conv[inside ? 1 : 0].out_row(y)[x0 + i];
    out[i] = encoder.encode(static_cast<double>(cost), cost < Conv::kInf, inside);
  }
}

// Passes B and C and encoding of a whole field through TruncatedMinConvolution: pass_slices'
// work, slice by slice, with the window the whole slice.
template <class T, class U>
void pass_slices_truncated(const Plan& p, const SolidRows& world, ChunkedVolume<U>& g, const Encoder<T>& encoder,
                           std::uint32_t cap) {
  using Conv = TruncatedMinConvolution;
  const int X = p.domain.size().x, Y = p.domain.size().y;
  const int by = p.domain.begin.y;
  const int reach = static_cast<int>(std::floor(p.clamp));
  const auto drop = static_cast<Conv::Cost>(std::floor(p.clamp * p.clamp));
  const int passes = p.is_signed ? 2 : 1;
  const std::size_t Z = static_cast<std::size_t>(p.domain.size().z);
  const std::size_t grain = std::max<std::size_t>(1, Z / (4 * static_cast<std::size_t>(max_threads())));
  parallel_for(Z, grain, [&](std::size_t zb, std::size_t ze) {
    Conv conv[2];
    std::vector<std::uint8_t> solid(p.is_signed ? static_cast<std::size_t>(X) * Y : 0);
    for (int k = 0; k < passes; ++k) conv[k].prepare(X, Y, 0, 0, X, Y, reach, drop);
    for (std::size_t zi = zb; zi < ze; ++zi) {
      const int z = p.domain.begin.z + static_cast<int>(zi);
      for (int y = 0; y < Y; ++y) {
        for_each_row_segment(p, g.edge, g.shift, [&](int cx, int lx, int count, int xo) {
          const std::size_t o = static_cast<std::size_t>(y) * X + xo;
          gather_truncated_row(g.row(cx, by + y, z) + lx, world.row(cx, by + y, z) + lx, count, cap, p.is_signed,
                               conv[0].f_row(y) + xo, p.is_signed ? conv[1].f_row(y) + xo : nullptr,
                               p.is_signed ? solid.data() + o : nullptr);
        });
      }
      for (int k = 0; k < passes; ++k) conv[k].solve();
      // Encode and write the final values back into the same slice.
      for (int y = 0; y < Y; ++y) {
        for_each_row_segment(p, g.edge, g.shift, [&](int cx, int lx, int count, int xo) {
          T* out = reinterpret_cast<T*>(g.row(cx, by + y, z)) + lx;  // T and U have the same size
          encode_truncated_row(encoder, conv, y, xo, count, p.is_signed ? solid.data() + static_cast<std::size_t>(y) * X + xo : nullptr,
                               out, drop);
        });
      }
    }
  });
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
  const double clamp_cost = p.metric == Metric::kEuclidean ? p.clamp * p.clamp : p.clamp;
  auto drop = [&](auto inf) {
    using V = decltype(inf);
    if (!(clamp_cost < static_cast<double>(inf))) return inf;
    if constexpr (std::is_integral_v<V>) return static_cast<V>(std::floor(clamp_cost));
    return static_cast<V>(clamp_cost);
  };
  if (p.metric == Metric::kManhattan) {
    auto solve = [sites](int X, int Y, SliceBuffers<std::int32_t>& b, int lo, int hi) { solve_slice_manhattan(X, Y, b, sites, lo, hi); };
    fn(std::int32_t{}, solve, detail::kManhattanInf);
  } else if (p.metric == Metric::kChebyshev) {
    auto k = [](int n, const std::int32_t* f, std::int32_t* o, std::int32_t* a, std::int32_t* s, std::int32_t* t) {
      detail::envelope_1d(Chebyshev{}, n, f, o, a, s, t);
    };
    auto solve = [k, sites, d = drop(Chebyshev::kInf)](int X, int Y, SliceBuffers<std::int32_t>& b, int lo, int hi) {
      solve_slice_envelope(k, k, X, Y, b, sites, Chebyshev::kInf, lo, hi, d);
    };
    fn(std::int32_t{}, solve, Chebyshev::kInf);
  } else if (p.unit_spacing && static_cast<double>(extent.x) * extent.x + static_cast<double>(extent.y) * extent.y +
                                       static_cast<double>(extent.z) * extent.z < (1 << 29)) {
    auto k = [](int n, const std::int32_t* f, std::int32_t* o, std::int32_t* a, std::int32_t* s, std::int32_t* t) {
      detail::envelope_1d(detail::EuclideanInt32{}, n, f, o, a, s, t);
    };
    auto solve = [k, sites, d = drop(detail::EuclideanInt32::kInf)](int X, int Y, SliceBuffers<std::int32_t>& b, int lo, int hi) {
      solve_slice_envelope(k, k, X, Y, b, sites, detail::EuclideanInt32::kInf, lo, hi, d);
    };
    fn(std::int32_t{}, solve, detail::EuclideanInt32::kInf);
  } else if (p.unit_spacing) {
    auto k = [](int n, const std::int64_t* f, std::int64_t* o, std::int32_t* a, std::int32_t* s, std::int32_t* t) {
      detail::envelope_1d(EuclideanInt{}, n, f, o, a, s, t);
    };
    auto solve = [k, sites, d = drop(EuclideanInt::kInf)](int X, int Y, SliceBuffers<std::int64_t>& b, int lo, int hi) {
      solve_slice_envelope(k, k, X, Y, b, sites, EuclideanInt::kInf, lo, hi, d);
    };
    fn(std::int64_t{}, solve, EuclideanInt::kInf);
  } else {
    const EuclideanReal ex{p.spacing[0] * p.spacing[0]}, ey{p.spacing[1] * p.spacing[1]};
    auto kx = [ex](int n, const double* f, double* o, std::int32_t* a, std::int32_t* s, std::int32_t* t) {
      detail::envelope_1d(ex, n, f, o, a, s, t);
    };
    auto ky = [ey](int n, const double* f, double* o, std::int32_t* a, std::int32_t* s, std::int32_t* t) {
      detail::envelope_1d(ey, n, f, o, a, s, t);
    };
    auto solve = [kx, ky, sites, d = drop(EuclideanReal::kInf)](int X, int Y, SliceBuffers<double>& b, int lo, int hi) {
      // The two axes weigh differently; the slice solver takes one kernel per axis.
      solve_slice_envelope2(kx, ky, X, Y, b, sites, EuclideanReal::kInf, lo, hi, d);
    };
    fn(double{}, solve, EuclideanReal::kInf);
  }
}

template <class T, class U>
DistanceField run(const Grid<std::uint8_t>& occupancy, const DistanceOptions& options, const Plan& p) {
  const T background = detail::field_background<T>(p);
  DistanceField out;
  out.options = options;
  out.domain = p.domain;
  out.encoding = p.encoding;
  const int edge = occupancy.chunk_edge();
  Grid<T> values(edge, background, occupancy.bounds());
  std::optional<Grid<SiteOffset>> sites_grid;
  if (p.sites) sites_grid.emplace(edge, SiteOffset{}, occupancy.bounds());
  if (p.domain.empty()) {
    out.values = std::move(values);
    out.sites = std::move(sites_grid);
    return out;
  }

  ChunkedVolume<U> g(p.aligned, edge);
  std::optional<ChunkedVolume<SiteOffset>> sites;
  if (p.sites) sites.emplace(p.aligned, edge);
  const SolidRows world(occupancy, p.aligned);

  // Chunks reaching outside the domain keep the background there.
  {
    U bg;
    std::memcpy(&bg, &background, sizeof(U));
    const std::size_t volume = std::size_t{1} << (3 * g.shift);
    parallel_for(g.chunks.size(), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const Vec3i lo{g.coords[i].x * edge, g.coords[i].y * edge, g.coords[i].z * edge};
        if (!p.domain.contains(Box3i{lo, lo + Vec3i::splat(edge)})) {
          std::fill(g.chunks[i].get(), g.chunks[i].get() + volume, bg);
          if (sites) std::fill(sites->chunks[i].get(), sites->chunks[i].get() + volume, SiteOffset{});
        }
      }
    });
  }

  // Largest g worth keeping: beyond it a column's site is farther than the clamp.
  constexpr std::uint64_t kInfU = std::numeric_limits<U>::max();
  std::uint64_t cap = kInfU;
  if (std::isfinite(p.clamp)) {
    const double vox = std::floor(p.clamp / p.spacing[2]) + 1;
    cap = static_cast<std::uint64_t>(std::min<double>(vox, static_cast<double>(kInfU)));
  }
  cap = std::min<std::uint64_t>(cap, std::numeric_limits<std::uint32_t>::max() - 1);
  const std::uint32_t cap32 = static_cast<std::uint32_t>(cap);

  // Pass A.
  const int ncx = g.nchunks.x, ncy = g.nchunks.y;
  parallel_for(static_cast<std::size_t>(ncx) * ncy, 1, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t> col;
    ChunkedVolume<SiteOffset>* sp = sites ? &*sites : nullptr;
    for (std::size_t i = b; i < e; ++i) {
      const int cx = static_cast<int>(i % ncx), cy = static_cast<int>(i / ncx);
      if (p.is_signed) {
        pass_z<U, true>(p, world, g, sp, cx, cy, cap32, col);
      } else {
        pass_z<U, false>(p, world, g, sp, cx, cy, cap32, col);
      }
    }
  });

  // Passes B and C, and encoding.
  const Encoder<T> encoder(p);
  ChunkedVolume<SiteOffset>* sp = sites ? &*sites : nullptr;
  if (truncated_passes(p, p.sites)) {
    pass_slices_truncated<T, U>(p, world, g, encoder, cap32);
  } else {
    dispatch_solver(p, p.domain.size(), [&](auto tag, const auto& solve, auto inf) {
      using V = decltype(tag);
      pass_slices<T, U, V>(p, world, g, sp, solve, encoder, cap32, inf);
    });
  }

  // Hand the chunks to the grids (uniform ones collapse).
  std::vector<std::unique_ptr<T[]>> typed(g.chunks.size());
  for (std::size_t i = 0; i < g.chunks.size(); ++i) typed[i].reset(reinterpret_cast<T*>(g.chunks[i].release()));
  values.adopt_chunks(g.coords, std::move(typed));
  if (sites) sites_grid->adopt_chunks(sites->coords, std::move(sites->chunks));
  out.values = std::move(values);
  out.sites = std::move(sites_grid);
  return out;
}

// ---- Local recomputation (incremental updates) -------------------------------------------------
//
// The values of a box `out` need only the sites within the clamp's reach of it, so they are
// computed on a dense box `in` (out grown by the reach) with the same passes as the whole-field
// transform: pass A over the columns of `in`, keeping g only for the slices of `out`; the slice
// passes over `in`'s x-y extent for those slices; encoding of `out`'s part. No chunk is
// allocated: the workspace is a few dense arrays of `in`'s size.

// G: the type g is kept in (8 bits when cap < 256, see z_sweep_step); dz only with 32 bits.
template <bool kSigned, class G>
void region_pass_z(const std::uint8_t* solid, Vec3i n, int z0, int z1, G cap, G* g, std::int16_t* dz) {
  const std::size_t nx = static_cast<std::size_t>(n.x), plane = nx * static_cast<std::size_t>(n.y);
  thread_local std::vector<G> col_scratch, ds_scratch, da_scratch;  // kept: see compute_region_impl
  std::vector<G>& col = col_scratch;
  std::vector<G>& ds = ds_scratch;
  std::vector<G>& da = da_scratch;
  col.resize(static_cast<std::size_t>(n.z) * nx);
  ds.resize(nx);
  da.resize(nx);
  std::vector<std::int32_t> ls(dz ? nx : 0), la(dz ? nx : 0);
  for (int y = 0; y < n.y; ++y) {
    G* __restrict dsr = ds.data();
    G* __restrict dar = da.data();
    std::fill(ds.begin(), ds.end(), cap);
    std::fill(da.begin(), da.end(), cap);
    for (int z = 0; z < n.z; ++z) {
      z_sweep_step<kSigned, G>(solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx, dsr, dar,
                               col.data() + static_cast<std::size_t>(z) * nx, nx, cap);
    }
    std::fill(ds.begin(), ds.end(), cap);
    std::fill(da.begin(), da.end(), cap);
    for (int z = n.z - 1; z >= z0; --z) {
      const std::uint8_t* __restrict w = solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx;
      const G* __restrict c = col.data() + static_cast<std::size_t>(z) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        const bool s = w[i] != 0;
        dsr[i] = s ? G{0} : std::min(static_cast<G>(dsr[i] + 1u), cap);
        if constexpr (kSigned) dar[i] = s ? std::min(static_cast<G>(dar[i] + 1u), cap) : G{0};
      }
      if (z >= z1) continue;
      G* __restrict out = g + static_cast<std::size_t>(z - z0) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        const G back = (kSigned && w[i] != 0) ? dar[i] : dsr[i];
        out[i] = std::min(c[i], back);
      }
    }
    if (!dz) continue;
    // Nearest site along z, below winning ties, for the slices of `out`.
    std::fill(ls.begin(), ls.end(), INT32_MIN / 2);
    std::fill(la.begin(), la.end(), INT32_MIN / 2);
    for (int z = 0; z < z1; ++z) {
      const std::uint8_t* w = solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) (w[i] != 0 ? ls[i] : la[i]) = z;
      if (z < z0) continue;
      std::int16_t* d = dz + static_cast<std::size_t>(z - z0) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        d[i] = static_cast<std::int16_t>(std::clamp((kSigned && w[i] != 0 ? la[i] : ls[i]) - z, -32768, 32767));
      }
    }
    std::fill(ls.begin(), ls.end(), INT32_MAX / 2);
    std::fill(la.begin(), la.end(), INT32_MAX / 2);
    for (int z = n.z - 1; z >= z0; --z) {
      const std::uint8_t* w = solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) (w[i] != 0 ? ls[i] : la[i]) = z;
      if (z >= z1) continue;
      std::int16_t* d = dz + static_cast<std::size_t>(z - z0) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        const std::int32_t above = (kSigned && w[i] != 0 ? la[i] : ls[i]) - z;
        if (above < -static_cast<std::int32_t>(d[i])) d[i] = static_cast<std::int16_t>(std::min(above, 32767));
      }
    }
  }
}

// The slice passes and encoding of compute_region_impl through TruncatedMinConvolution: for
// unit-spacing Euclidean fields without nearest sites whose clamp D is below kMaxReach + 1.
template <class T>
void region_slices_truncated(const Plan& p, const Encoder<T>& encoder, Vec3i n, const Box3i& out, int ox, int oy, int z0,
                             std::uint8_t cap, const std::uint8_t* solid, const std::uint8_t* g, T* values) {
  using Conv = TruncatedMinConvolution;
  const Vec3i m = out.size();
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  const int reach = static_cast<int>(std::floor(p.clamp));               // |k| beyond it costs more than D²
  const auto drop = static_cast<Conv::Cost>(std::floor(p.clamp * p.clamp));  // integer costs above D² are beyond D
  const std::size_t grain = std::max<std::size_t>(1, (std::size_t{1} << 14) / plane);
  parallel_for(static_cast<std::size_t>(m.z), grain, [&](std::size_t zb, std::size_t ze) {
    thread_local Conv kept[2];
    Conv* conv = kept;
    const int passes = p.is_signed ? 2 : 1;
    for (int k = 0; k < passes; ++k) conv[k].prepare(n.x, n.y, ox, oy, m.x, m.y, reach, drop);
    for (std::size_t zi = zb; zi < ze; ++zi) {
      const std::uint8_t* gs = g + zi * plane;
      const std::uint8_t* ws = solid + (static_cast<std::size_t>(z0) + zi) * plane;
      // `ws` already says which voxels are solid: no copy of it is needed.
      for (int y = 0; y < n.y; ++y)
        gather_truncated_row(gs + static_cast<std::size_t>(y) * n.x, ws + static_cast<std::size_t>(y) * n.x, n.x, cap,
                             p.is_signed, conv[0].f_row(y), p.is_signed ? conv[1].f_row(y) : nullptr, nullptr);
      for (int k = 0; k < passes; ++k) conv[k].solve();
      for (int y = 0; y < m.y; ++y)
        encode_truncated_row(encoder, conv, y, 0, m.x, ws + static_cast<std::size_t>(y + oy) * n.x + static_cast<std::size_t>(ox),
                             values + (zi * static_cast<std::size_t>(m.y) + static_cast<std::size_t>(y)) * m.x, drop);
    }
  });
}

template <class T>
void compute_region_impl(const Grid<std::uint8_t>& occupancy, const Plan& p, const Box3i& in, const Box3i& out,
                         T* values, SiteOffset* sites, const Box3i* sites_within) {
  const Vec3i n = in.size(), m = out.size();
  const int z0 = out.begin.z - in.begin.z, z1 = out.end.z - in.begin.z;
  const int ox = out.begin.x - in.begin.x, oy = out.begin.y - in.begin.y;
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  // Scratch kept per thread across calls: incremental updates call this for every edit, and fresh
  // allocations of this size come from mmap, paying a page fault per 4 KiB every time.
  // (Named through references: a lambda naming a thread_local directly would reach the worker
  // thread's own copy, not this one.)
  thread_local std::vector<std::uint8_t> solid_scratch;
  thread_local std::vector<std::uint32_t> g_scratch;
  thread_local std::vector<std::int16_t> dz_scratch;
  std::vector<std::uint8_t>& solid = solid_scratch;
  std::vector<std::uint32_t>& g = g_scratch;
  std::vector<std::int16_t>& dz = dz_scratch;
  solid.resize(static_cast<std::size_t>(in.volume()));
  const Box3i site_box = sites_within ? sites_within->intersect(in) : in;
  if (site_box == in) {
    occupancy.copy_to_dense(in, solid.data());
  } else {  // empty everywhere but the sites' box, copied row by row into place
    std::fill(solid.begin(), solid.end(), std::uint8_t{0});
    if (!site_box.empty()) {
      thread_local std::vector<std::uint8_t> part_scratch;
      std::vector<std::uint8_t>& part = part_scratch;
      part.resize(static_cast<std::size_t>(site_box.volume()));
      occupancy.copy_to_dense(site_box, part.data());
      const Vec3i sn = site_box.size();
      for (int z = 0; z < sn.z; ++z)
        for (int y = 0; y < sn.y; ++y)
          std::copy_n(part.data() + (static_cast<std::size_t>(z) * sn.y + static_cast<std::size_t>(y)) * sn.x, sn.x,
                      solid.data() + (static_cast<std::size_t>(site_box.begin.z - in.begin.z + z) * n.y +
                                      static_cast<std::size_t>(site_box.begin.y - in.begin.y + y)) * n.x +
                          static_cast<std::size_t>(site_box.begin.x - in.begin.x));
    }
  }
  std::uint64_t cap = std::numeric_limits<std::uint32_t>::max() - 1;
  if (std::isfinite(p.clamp)) cap = std::min<std::uint64_t>(cap, static_cast<std::uint64_t>(std::floor(p.clamp / p.spacing[2]) + 1));
  const auto cap32 = static_cast<std::uint32_t>(cap);
  const Encoder<T> encoder(p);
  const double clamp_cost = p.metric == Metric::kEuclidean ? p.clamp * p.clamp : p.clamp;
  const bool euclid = p.metric == Metric::kEuclidean;
  // Small clamps (the usual case for editable worlds), unit spacing, no nearest sites: the 2-D
  // passes as truncated min-convolutions on the window alone (truncated_min_convolution.h), and g
  // in 8-bit lanes (cap <= kMaxReach + 1).
  if (truncated_passes(p, sites != nullptr)) {
    thread_local std::vector<std::uint8_t> g8_scratch;
    std::vector<std::uint8_t>& g8 = g8_scratch;
    g8.resize(static_cast<std::size_t>(m.z) * plane);
    const auto cap8 = static_cast<std::uint8_t>(cap);
    if (p.is_signed) {
      region_pass_z<true>(solid.data(), n, z0, z1, cap8, g8.data(), nullptr);
    } else {
      region_pass_z<false>(solid.data(), n, z0, z1, cap8, g8.data(), nullptr);
    }
    region_slices_truncated(p, encoder, n, out, ox, oy, z0, cap8, solid.data(), g8.data(), values);
    return;
  }
  g.resize(static_cast<std::size_t>(m.z) * plane);
  dz.resize(sites ? g.size() : 0);
  if (p.is_signed) {
    region_pass_z<true>(solid.data(), n, z0, z1, cap32, g.data(), sites ? dz.data() : nullptr);
  } else {
    region_pass_z<false>(solid.data(), n, z0, z1, cap32, g.data(), sites ? dz.data() : nullptr);
  }
  dispatch_solver(p, n, [&](auto tag, const auto& solve, auto inf) {
    using V = decltype(tag);
    const V clamp_v = clamp_cost >= static_cast<double>(inf) ? inf : static_cast<V>(clamp_cost);
    const int passes = p.is_signed ? 2 : 1;
    // Small regions (most edits) run on the calling thread: handing ~10 slices to a pool costs
    // more than computing them. Slice buffers of moderate size are kept per thread across calls.
    const std::size_t grain = std::max<std::size_t>(1, (std::size_t{1} << 14) / plane);
    parallel_for(static_cast<std::size_t>(m.z), grain, [&](std::size_t zb, std::size_t ze) {
      thread_local SliceBuffers<V> kept[2];
      SliceBuffers<V> own[2];
      SliceBuffers<V>* buf = plane <= (std::size_t{1} << 16) ? kept : own;
      for (int k = 0; k < passes; ++k) buf[k].resize(n.x, n.y);
      for (std::size_t zi = zb; zi < ze; ++zi) {
        const std::uint32_t* gs = g.data() + zi * plane;
        const std::uint8_t* ws = solid.data() + (static_cast<std::size_t>(z0) + zi) * plane;
        for (std::size_t i = 0; i < plane; ++i) {
          V c;
          if (gs[i] >= cap32) {
            c = inf;
          } else if (euclid) {
            const double gz = p.unit_spacing ? static_cast<double>(gs[i]) : p.spacing[2] * gs[i];
            c = gz * gz > clamp_cost ? inf : static_cast<V>(gz * gz);
          } else {
            c = static_cast<V>(gs[i]);
          }
          if (p.is_signed) {
            buf[1].f[i] = ws[i] ? c : V(0);
            buf[0].f[i] = ws[i] ? V(0) : c;
          } else {
            buf[0].f[i] = c;
          }
        }
        for (int k = 0; k < passes; ++k) solve(n.x, n.y, buf[k], ox, ox + m.x);
        if (encoder.row_path && !sites) {
          for (int y = 0; y < m.y; ++y) {
            encoder.encode_row(buf[0].h.data() + static_cast<std::size_t>(y + oy) * n.x + static_cast<std::size_t>(ox),
                               values + (zi * static_cast<std::size_t>(m.y) + static_cast<std::size_t>(y)) * m.x, m.x, inf,
                               clamp_v);
          }
          continue;
        }
        for (int y = 0; y < m.y; ++y)
          for (int x = 0; x < m.x; ++x) {
            const std::size_t i = static_cast<std::size_t>(y + oy) * n.x + static_cast<std::size_t>(x + ox);
            const std::size_t o = (zi * static_cast<std::size_t>(m.y) + static_cast<std::size_t>(y)) * m.x + static_cast<std::size_t>(x);
            const bool inside = p.is_signed && ws[i];
            const SliceBuffers<V>& b = buf[inside ? 1 : 0];
            const V cost = b.h[i];
            const bool has_site = cost < inf && cost <= clamp_v;
            values[o] = encoder.encode(static_cast<double>(cost), has_site, inside);
            if (!sites) continue;
            SiteOffset so;
            if (has_site) {
              const std::int32_t ys = b.arg_y[i];
              const std::int32_t xs = b.arg_x[static_cast<std::size_t>(ys) * n.x + static_cast<std::size_t>(x + ox)];
              so.dx = static_cast<std::int16_t>(xs - (x + ox));
              so.dy = static_cast<std::int16_t>(ys - (y + oy));
              const std::size_t col = static_cast<std::size_t>(ys) * n.x + static_cast<std::size_t>(xs);
              const bool column_is_site = p.is_signed ? (ws[col] != 0) != inside : ws[col] != 0;
              so.dz = column_is_site ? std::int16_t{0} : dz[zi * plane + col];
            }
            sites[o] = so;
          }
      }
    });
  });
}

Box3i chunk_aligned(const Box3i& b, int shift) {
  const int e = 1 << shift;
  const Vec3i lo{(b.begin.x >> shift) * e, (b.begin.y >> shift) * e, (b.begin.z >> shift) * e};
  const Vec3i hi{((b.end.x - 1) >> shift) * e + e, ((b.end.y - 1) >> shift) * e + e, ((b.end.z - 1) >> shift) * e + e};
  return {lo, hi};
}

}  // namespace

const char* metric_name(Metric m) {
  switch (m) {
    case Metric::kManhattan: return "manhattan";
    case Metric::kChebyshev: return "chebyshev";
    case Metric::kEuclidean: return "euclidean";
  }
  return "?";
}

const char* storage_name(Storage s) {
  switch (s) {
    case Storage::kU8: return "u8";
    case Storage::kU16: return "u16";
    case Storage::kF32: return "f32";
  }
  return "?";
}

Metric parse_metric(const std::string& name) {
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    if (name == metric_name(m)) return m;
  throw InvalidArgument("unknown metric \"" + name + "\" (manhattan, chebyshev, euclidean)");
}

Storage parse_storage(const std::string& name) {
  for (Storage s : {Storage::kU8, Storage::kU16, Storage::kF32})
    if (name == storage_name(s)) return s;
  throw InvalidArgument("unknown storage \"" + name + "\" (u8, u16, f32)");
}

double DistanceField::distance(Vec3i p) const {
  return std::visit([&](const auto& g) { return encoding.decode(static_cast<double>(g.get(p))); }, values);
}

int DistanceField::chunk_edge() const {
  return std::visit([](const auto& g) { return g.chunk_edge(); }, values);
}

DistanceField compute_distance_field(const World& world, const DistanceOptions& options) {
  return compute_distance_field(world.voxels, options);
}

namespace detail {

FieldPlan make_field_plan(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o) {
  if (!(o.max_distance >= 0) || std::isinf(o.max_distance)) {
    throw InvalidArgument("max distance must be a finite number >= 0 (0 = no clamp)");
  }
  for (double s : o.spacing)
    if (!(s > 0) || !std::isfinite(s)) throw InvalidArgument("voxel spacing must be positive and finite");
  const bool unit_spacing = o.spacing == std::array<double, 3>{1, 1, 1};
  if (!unit_spacing && o.metric != Metric::kEuclidean) {
    throw InvalidArgument(std::string("voxel spacing applies to the euclidean metric only, not ") + metric_name(o.metric));
  }
  if (o.fixed_point_scale < 0 || !std::isfinite(o.fixed_point_scale)) {
    throw InvalidArgument("fixed-point scale must be >= 0");
  }
  FieldPlan p;
  p.metric = o.metric;
  p.is_signed = o.signed_distance;
  p.sites = o.nearest_sites;
  p.unit_spacing = unit_spacing;
  p.spacing = o.spacing;
  p.clamp = o.max_distance > 0 ? o.max_distance : std::numeric_limits<double>::infinity();

  // Encoding.
  if (o.storage != Storage::kF32) {
    const int bits = o.storage == Storage::kU8 ? 8 : 16;
    p.encoding.scale = o.metric != Metric::kEuclidean ? 1.0
                       : o.fixed_point_scale > 0      ? o.fixed_point_scale
                                                      : (bits == 8 ? 4.0 : 16.0);
    p.encoding.bias = o.signed_distance ? (std::int64_t{1} << (bits - 1)) : 0;
    // Integer storage cannot hold more than its range: that range acts as a clamp.
    const double type_max = static_cast<double>((std::int64_t{1} << bits) - 1);
    const double range = (type_max - static_cast<double>(p.encoding.bias)) / p.encoding.scale;
    p.clamp = std::min(p.clamp, range);
    // g is held in place in the output type: it must reach past the clamp along z.
    if (type_max * o.spacing[2] < p.clamp) {
      throw InvalidArgument("voxel spacing " + std::to_string(o.spacing[2]) + " along z is too fine for " +
                            storage_name(o.storage) + " storage with this clamp; use f32");
    }
  }

  // Domain.
  if (o.domain) {
    p.domain = *o.domain;
  } else if (occupancy.bounds()) {
    p.domain = *occupancy.bounds();
  } else {
    const Box3i content = occupancy.content_bounds();
    const double grow = o.max_distance > 0 ? std::ceil(o.max_distance / std::min({o.spacing[0], o.spacing[1], o.spacing[2]})) : 1.0;
    p.domain = content.empty() ? content : content.grown(static_cast<std::int32_t>(std::min(grow, 1e6)));
  }
  if (!p.domain.empty()) {
    const Vec3i s = p.domain.size();
    const std::int64_t limit = o.nearest_sites ? 32767 : (std::int64_t{1} << 30);
    if (s.x > limit || s.y > limit || s.z > limit) {
      throw InvalidArgument("domain " + to_string(p.domain) + " is too large" +
                            (o.nearest_sites ? std::string(" for 16-bit nearest-site offsets") : std::string()));
    }
    p.aligned = chunk_aligned(p.domain, occupancy.chunk_shift());
    // The values over the domain (and the sites) are what the field holds at most: refuse a
    // domain they cannot fit in before anything is allocated.
    const std::uint64_t per_voxel = (o.storage == Storage::kU8 ? 1 : o.storage == Storage::kU16 ? 2 : 4) +
                                    (o.nearest_sites ? sizeof(SiteOffset) : 0);
    require_memory(dense_bytes(p.domain, per_voxel), 0, "distance field",
                   "the domain " + to_string(p.domain) + " of " + std::to_string(p.domain.volume()) + " voxels");
  }
  return p;
}

template <class T>
void compute_region(const Grid<std::uint8_t>& occupancy, const FieldPlan& p, const Box3i& in, const Box3i& out,
                    T* values, SiteOffset* sites, const Box3i* sites_within) {
  if (!in.contains(out)) throw InvalidArgument("compute_region: the input box must contain the output box");
  if (out.empty()) return;
  compute_region_impl<T>(occupancy, p, in, out, values, sites, sites_within);
}
template void compute_region<std::uint8_t>(const Grid<std::uint8_t>&, const FieldPlan&, const Box3i&, const Box3i&, std::uint8_t*, SiteOffset*, const Box3i*);
template void compute_region<std::uint16_t>(const Grid<std::uint8_t>&, const FieldPlan&, const Box3i&, const Box3i&, std::uint16_t*, SiteOffset*, const Box3i*);
template void compute_region<float>(const Grid<std::uint8_t>&, const FieldPlan&, const Box3i&, const Box3i&, float*, SiteOffset*, const Box3i*);

}  // namespace detail

DistanceField compute_distance_field(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o) {
  const Plan p = detail::make_field_plan(occupancy, o);
  switch (o.storage) {
    case Storage::kU8:
      return run<std::uint8_t, std::uint8_t>(occupancy, o, p);
    case Storage::kU16:
      return run<std::uint16_t, std::uint16_t>(occupancy, o, p);
    case Storage::kF32:
      return run<float, std::uint32_t>(occupancy, o, p);
  }
  throw InvalidArgument("unknown storage");
}

}  // namespace voxfield
