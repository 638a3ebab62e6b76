// voxfield — the 2-D passes of a clamped Euclidean transform on a window of one slice, by
// truncated min-convolution (internal; used by exact/local_region.cpp for local recomputation, and
// by exact/whole_field.cpp for whole fields with the whole slice as the window).
//
// After the z pass, a slice holds f(x, y) = dz², the squared distance to the nearest site in each
// column. The squared Euclidean distance transform then is two min-convolutions with the parabola
// k² (Felzenszwalb & Huttenlocher, "Distance Transforms of Sampled Functions", Theory of
// Computing 8, 2012):
//     h(x, y) = min_k f(x + k, y) + k²        (along x)
//     d(x, y) = min_k h(x, y + k) + k²        (along y)
// The lower-envelope scan does each line in linear time whatever the reach. With a clamp D,
// however, only |k| <= D can matter: a term with |k| > D costs more than D² on its own, and every
// cost above floor(D²) is "no site within the clamp" anyway — so the truncated sums give exactly
// the envelope's clamped results (integer costs, one minimum: no ties to break). For the small
// clamps of editable worlds (D of 16 or 32) the truncated form wins by a wide margin on the small
// boxes an edit recomputes, and stays ahead on whole slices up to kMaxReach (measurements in
// docs/benchmarks.md):
//  - only the window's columns (pass along x) and rows (pass along y) are computed, where the
//    envelope must scan and fill whole lines;
//  - costs fit 16-bit lanes (D <= kMaxReach), so each step is an add and a min over 8 voxels at
//    once (SSE2's paddw / pminsw), with no division and no data-dependent branch;
//  - the pass along y runs on whole rows, so no transposes, and rows without any site are
//    skipped (after a placement in open air most rows have none).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace voxfield::detail {

class TruncatedMinConvolution {
 public:
  using Cost = std::int16_t;
  // "No site": above every real cost (at most 2 * kMaxReach² before dropping), and far enough
  // below the 16-bit limit that kInf + k² cannot overflow.
  static constexpr Cost kInf = 0x4000;
  static constexpr int kMaxReach = 64;

  // A slice of nx * ny costs of which the window of mx * my voxels at (ox, oy) is wanted, with
  // clamp reach `reach` voxels (1 <= reach <= kMaxReach) and costs above `drop` (floor of the
  // squared clamp) as "no site". Contents are not kept; storage is, across calls.
  void prepare(int nx, int ny, int ox, int oy, int mx, int my, int reach, Cost drop) {
    nx_ = nx;
    ny_ = ny;
    ox_ = ox;
    oy_ = oy;
    mx_ = mx;
    my_ = my;
    reach_ = reach;
    drop_ = drop;
    // The window's width rounded up to whole vectors (16 lanes: two SSE registers per step), so
    // the inner loops have no scalar tail; the extra columns compute values nobody reads.
    mw_ = (mx + 15) & ~15;
    // Rows of f keep `reach` columns of "no site" before x = 0 and enough after nx for the
    // widened window's last column to look `reach` beyond it.
    stride_ = reach + std::max(nx, ox + mw_) + reach;
    f_.assign(static_cast<std::size_t>(stride_) * static_cast<std::size_t>(ny), kInf);
    h_.resize(static_cast<std::size_t>(mw_) * static_cast<std::size_t>(ny));
    live_.resize(static_cast<std::size_t>(ny));
    out_.resize(static_cast<std::size_t>(mw_) * static_cast<std::size_t>(my));
  }

  // Where to write row y's nx costs (f, squared voxel units; kInf for no site in the column).
  // Only those nx entries may be written: the padding around them stays "no site".
  Cost* f_row(int y) {
    return f_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(stride_) +
           static_cast<std::size_t>(reach_);
  }

  // Both passes. Afterwards out_row(j) holds the squared distances (kInf when beyond the clamp) of
  // the window's row j, columns 0..mx-1.
  void solve() {
    // Members are read once into locals: the stores to live_ are through unsigned char, which may
    // alias anything, so otherwise every member would be reloaded after each of them.
    const int reach = reach_, mw = mw_, ox = ox_, oy = oy_, ny = ny_, my = my_;
    const Cost drop = drop_;
    const std::size_t row_h = static_cast<std::size_t>(mw),
                      row_f = static_cast<std::size_t>(stride_);
    const Cost* const f_all = f_.data() + reach;
    Cost* const h_all = h_.data();
    Cost* const out_all = out_.data();
    std::uint8_t* const live = live_.data();
    const int lo = ox - reach, hi = ox + mw + reach;  // columns of f the window's results read
    // Pass along x, on the window's columns only, for every row with a site in reach of it.
    for (int y = 0; y < ny; ++y) {
      const Cost* __restrict f = f_all + static_cast<std::size_t>(y) * row_f;
      Cost m = kInf;
      for (int x = lo; x < hi; ++x) m = std::min(m, f[x]);
      live[y] = m < kInf;
      if (m >= kInf) continue;
      Cost* __restrict h = h_all + static_cast<std::size_t>(y) * row_h;
      std::fill(h, h + mw, kInf);
      for (int k = -reach; k <= reach; ++k) {
        const Cost w = static_cast<Cost>(k * k);
        const Cost* __restrict src = f + ox + k;
        for (int j = 0; j < mw; ++j) h[j] = std::min(h[j], static_cast<Cost>(src[j] + w));
      }
      // A cost above the clamp cannot come back within it: one less term for the next pass.
      for (int j = 0; j < mw; ++j) h[j] = h[j] > drop ? kInf : h[j];
    }
    // Pass along y, whole rows at a time, for the window's rows.
    for (int j = 0; j < my; ++j) {
      const int y = oy + j;
      Cost* __restrict d = out_all + static_cast<std::size_t>(j) * row_h;
      std::fill(d, d + mw, kInf);
      for (int k = std::max(-reach, -y); k <= std::min(reach, ny - 1 - y); ++k) {
        if (!live[y + k]) continue;
        const Cost w = static_cast<Cost>(k * k);
        const Cost* __restrict src = h_all + static_cast<std::size_t>(y + k) * row_h;
        for (int i = 0; i < mw; ++i) d[i] = std::min(d[i], static_cast<Cost>(src[i] + w));
      }
      for (int i = 0; i < mw; ++i) d[i] = d[i] > drop ? kInf : d[i];
    }
  }

  const Cost* out_row(int j) const {
    return out_.data() + static_cast<std::size_t>(j) * static_cast<std::size_t>(mw_);
  }

 private:
  int nx_ = 0, ny_ = 0, ox_ = 0, oy_ = 0, mx_ = 0, my_ = 0, reach_ = 0, mw_ = 0, stride_ = 0;
  Cost drop_ = 0;
  std::vector<Cost> f_, h_, out_;
  std::vector<std::uint8_t> live_;
};

}  // namespace voxfield::detail
