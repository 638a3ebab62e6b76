// The one-dimensional Euclidean kernels of the exact transform (src/distance/line_transforms.h)
// against brute force: every voxel's minimum of (x - i)^2 + f[i] and its smallest minimising index,
// on random lines built to hold ties (small costs over few distinct values), lines without sites,
// single sites, and lines at the 32-bit kernel's bounds (n^2 and the costs near 2^29). The
// division-free kernel must also agree with Meijster's scan, value for value and site for site,
// and its lock-step form (envelope_lanes.h) with it, lane by lane; the windowed min-plus
// (window_lanes.h), in SSE registers and in plain loops, with it lane by lane, values only; and the
// local passes' two-dimensional truncated min-convolution against its definition.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "distance/envelope_lanes.h"
#include "distance/line_transforms.h"
#include "distance/truncated_min_convolution.h"
#include "distance/window_lanes.h"

using namespace voxfield::detail;

namespace {

constexpr std::int32_t kInf = EuclideanInt32::kInf;

// Brute force at x: the minimum and the smallest i reaching it (-1 and kInf without a site).
std::pair<std::int32_t, std::int32_t> brute_force_at(const std::vector<std::int32_t>& f, int x) {
  std::int64_t best = kInf;
  std::int32_t site = -1;
  for (int i = 0; i < static_cast<int>(f.size()); ++i) {
    if (!(f[i] < kInf)) continue;
    const std::int64_t c = std::int64_t{x - i} * (x - i) + f[i];
    if (c < best) {
      best = c;
      site = i;
    }
  }
  return {static_cast<std::int32_t>(best), site};
}

struct LineResult {
  std::vector<std::int32_t> out, arg;
};

LineResult division_free(const std::vector<std::int32_t>& f) {
  const int n = static_cast<int>(f.size());
  LineResult r{std::vector<std::int32_t>(n), std::vector<std::int32_t>(n)};
  std::vector<std::int32_t> s(n), h(n);
  envelope_euclidean_int32(n, f.data(), r.out.data(), r.arg.data(), s.data(), h.data());
  return r;
}

LineResult meijster(const std::vector<std::int32_t>& f) {
  const int n = static_cast<int>(f.size());
  LineResult r{std::vector<std::int32_t>(n), std::vector<std::int32_t>(n)};
  std::vector<std::int32_t> s(n), t(n);
  envelope_1d(EuclideanInt32{}, n, f.data(), r.out.data(), r.arg.data(), s.data(), t.data());
  return r;
}

}  // namespace

TEST(LineTransforms, TheDivisionFreeEnvelopeEqualsBruteForceOnRandomLinesWithTies) {
  std::mt19937 rng(29);
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 90);
    // Costs from a few small values (squares and non-squares), so that parabolas tie often; a
    // share of voxels without a site, and some lines with none at all.
    const int air_percent = trial % 10 == 0 ? 100 : static_cast<int>(rng() % 90);
    const int spread = 1 + static_cast<int>(rng() % 40);
    std::vector<std::int32_t> f(n);
    for (auto& v : f)
      v = static_cast<int>(rng() % 100) < air_percent ? kInf
                                                      : static_cast<std::int32_t>(rng() % spread);
    const LineResult got = division_free(f);
    const LineResult ref = meijster(f);
    for (int x = 0; x < n; ++x) {
      const auto [value, site] = brute_force_at(f, x);
      ASSERT_EQ(got.out[x], value) << "trial " << trial << ", x " << x;
      ASSERT_EQ(got.arg[x], site) << "trial " << trial << ", x " << x;
      ASSERT_EQ(ref.out[x], value) << "trial " << trial << ", x " << x;
      ASSERT_EQ(ref.arg[x], site) << "trial " << trial << ", x " << x;
    }
  }
}

TEST(LineTransforms, TheDivisionFreeEnvelopeHoldsAtTheThirtyTwoBitBounds) {
  // The kernel's domain: n^2 + the largest finite cost below 2^30, products in 64 bits.
  std::mt19937 rng(7);
  const int n = 23170;  // n^2 < 2^29
  std::vector<std::int32_t> f(n);
  for (auto& v : f) {
    const std::uint32_t r = rng();
    v = r % 3 == 0 ? kInf : static_cast<std::int32_t>(r % static_cast<std::uint32_t>(kInf));
  }
  f[n - 1] = kInf - 1;  // the largest finite cost, at the far end
  const LineResult got = division_free(f);
  const LineResult ref = meijster(f);
  EXPECT_EQ(got.out, ref.out);
  EXPECT_EQ(got.arg, ref.arg);
  for (int x = 0; x < n; x += 97) {
    const auto [value, site] = brute_force_at(f, x);
    ASSERT_EQ(got.out[x], value) << "x " << x;
    ASSERT_EQ(got.arg[x], site) << "x " << x;
  }
}

TEST(LineTransforms, LinesWithOneSiteOrNoneGiveItsParabolaOrNothing) {
  for (int n : {1, 2, 7, 64}) {
    std::vector<std::int32_t> none(n, kInf);
    const LineResult empty = division_free(none);
    for (int x = 0; x < n; ++x) {
      EXPECT_EQ(empty.out[x], kInf);
      EXPECT_EQ(empty.arg[x], -1);
    }
    std::vector<std::int32_t> one(n, kInf);
    one[n / 2] = 5;
    const LineResult r = division_free(one);
    for (int x = 0; x < n; ++x) {
      EXPECT_EQ(r.out[x], (x - n / 2) * (x - n / 2) + 5);
      EXPECT_EQ(r.arg[x], n / 2);
    }
  }
}

namespace {

// Four lines through the lock-step kernel at once; each lane's result, as division_free's.
std::vector<LineResult> four_lanes(const std::vector<std::vector<std::int32_t>>& lines,
                                   bool with_sites) {
  const int n = static_cast<int>(lines[0].size());
  std::vector<LineResult> r(
      4, LineResult{std::vector<std::int32_t>(n, -7), std::vector<std::int32_t>(n, -7)});
  const std::int32_t* f[4];
  std::int32_t* out[4];
  std::int32_t* arg[4];
  for (int k = 0; k < 4; ++k) {
    f[k] = lines[k].data();
    out[k] = r[k].out.data();
    arg[k] = r[k].arg.data();
  }
  std::vector<std::int32_t> s(4 * envelope_lane_stride(n)), h(4 * envelope_lane_stride(n));
  envelope_euclidean_int32_lanes<4>(n, f, out, with_sites ? arg : nullptr, s.data(), h.data());
  return r;
}

}  // namespace

TEST(LineTransforms, TheLockStepEnvelopeEqualsTheOneLineKernelInEveryLane) {
  // Lanes of one batch differ in how many sites they hold and how many pops they need, so they
  // finish building and writing back at different steps.
  std::mt19937 rng(113);
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 120);
    std::vector<std::vector<std::int32_t>> lines(4, std::vector<std::int32_t>(n));
    for (auto& line : lines) {
      const int air_percent = static_cast<int>(rng() % 100);
      const int spread = 1 + static_cast<int>(rng() % (trial % 3 == 0 ? 4 : 3000));
      for (auto& v : line)
        v = static_cast<int>(rng() % 100) < air_percent ? kInf
                                                        : static_cast<std::int32_t>(rng() % spread);
      line[rng() % n] = static_cast<std::int32_t>(rng() % spread);  // at least one site
    }
    const bool with_sites = trial % 2 == 0;
    const std::vector<LineResult> got = four_lanes(lines, with_sites);
    for (int k = 0; k < 4; ++k) {
      const LineResult ref = division_free(lines[k]);
      ASSERT_EQ(got[k].out, ref.out) << "trial " << trial << ", lane " << k;
      if (with_sites) {
        ASSERT_EQ(got[k].arg, ref.arg) << "trial " << trial << ", lane " << k;
      } else {
        ASSERT_EQ(got[k].arg, std::vector<std::int32_t>(n, -7)) << "sites written unasked";
      }
      const auto [value, site] = brute_force_at(lines[k], n - 1);
      ASSERT_EQ(got[k].out[n - 1], value);
      if (with_sites) {
        ASSERT_EQ(got[k].arg[n - 1], site);
      }
    }
  }
}

TEST(LineTransforms, TheLockStepEnvelopeLeavesOutZeroCostSitesInsideTheirRunsExactly) {
  // Lines as real volumes give them: runs of solid matter (cost 0), of air beyond the clamp (no
  // site) and of costs from earlier passes. The kernel builds only the ends of each zero run.
  std::mt19937 rng(2027);
  for (int trial = 0; trial < 3000; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 200);
    std::vector<std::vector<std::int32_t>> lines(4, std::vector<std::int32_t>(n));
    for (auto& line : lines) {
      for (int x = 0; x < n;) {
        const int run = 1 + static_cast<int>(rng() % 40);
        const int kind = static_cast<int>(rng() % 3);
        for (int i = 0; i < run && x < n; ++i, ++x)
          line[x] = kind == 0 ? 0 : kind == 1 ? kInf : static_cast<std::int32_t>(rng() % 900);
      }
      line[rng() % n] = 0;  // at least one site
    }
    const bool with_sites = trial % 2 == 0;
    const std::vector<LineResult> got = four_lanes(lines, with_sites);
    for (int k = 0; k < 4; ++k) {
      const LineResult ref = division_free(lines[k]);
      ASSERT_EQ(got[k].out, ref.out) << "trial " << trial << ", lane " << k;
      if (with_sites) {
        ASSERT_EQ(got[k].arg, ref.arg) << "trial " << trial << ", lane " << k;
      }
      for (int x = 0; x < n; x += 7) {
        const auto [value, site] = brute_force_at(lines[k], x);
        ASSERT_EQ(got[k].out[x], value) << "trial " << trial << ", lane " << k << ", x " << x;
        if (with_sites) {
          ASSERT_EQ(got[k].arg[x], site);
        }
      }
    }
  }
}

template <class L>
void check_windowed_lanes() {
  // Eight lines interleaved (lane k of element i at i * stride + k, inside a wider array), of
  // every kind: no site, one site far away, dense costs, runs of solid matter. With a budget
  // large enough every lane equals the envelope's values; with a small one the kernel may give
  // up (false) but never returns true with a wrong value.
  std::mt19937 rng(77);
  int gave_up = 0, solved = 0;
  for (int trial = 0; trial < 1500; ++trial) {
    const int n = 1 + static_cast<int>(rng() % 150);
    const std::size_t stride = kWindowLanes + rng() % 5;
    std::vector<std::vector<std::int32_t>> lines(kWindowLanes, std::vector<std::int32_t>(n));
    for (auto& line : lines) {
      const int kind = static_cast<int>(rng() % 4);
      for (int x = 0; x < n; ++x) {
        const std::uint32_t r = rng();
        line[x] = kind == 0   ? kInf
                  : kind == 1 ? (r % 97 == 0 ? static_cast<std::int32_t>(r % 50) : kInf)
                  : kind == 2
                      ? static_cast<std::int32_t>(r % 2000)
                      : (r % 3 == 0 ? 0 : (r % 3 == 1 ? kInf : static_cast<std::int32_t>(r % 40)));
      }
    }
    std::vector<std::int32_t> f(static_cast<std::size_t>(n) * stride, -5);
    std::vector<std::int32_t> out(f.size(), -9);
    for (int k = 0; k < kWindowLanes; ++k)
      for (int x = 0; x < n; ++x) f[static_cast<std::size_t>(x) * stride + k] = lines[k][x];
    const bool small_budget = trial % 3 == 0;
    const std::int64_t budget =
        small_budget ? 4 * static_cast<std::int64_t>(n) : std::int64_t{1} << 40;
    const bool ok = window_min_plus_lanes<L>(n, f.data(), stride, out.data(), stride, budget);
    if (!small_budget) {
      ASSERT_TRUE(ok) << "trial " << trial;
    }
    if (!ok) {
      ++gave_up;
      continue;
    }
    ++solved;
    for (int k = 0; k < kWindowLanes; ++k) {
      const LineResult ref = division_free(lines[k]);
      for (int x = 0; x < n; ++x)
        ASSERT_EQ(out[static_cast<std::size_t>(x) * stride + k], std::min(ref.out[x], kInf))
            << "trial " << trial << ", lane " << k << ", x " << x;
    }
    for (std::size_t i = 0; i < out.size(); ++i)
      if (i % stride >= static_cast<std::size_t>(kWindowLanes)) {
        ASSERT_EQ(out[i], -9) << "wrote outside its lanes";
      }
  }
  EXPECT_GT(gave_up, 50);  // the small budgets do run out on the sparse lines
  EXPECT_GT(solved, 1000);
}

TEST(LineTransforms, TheWindowedMinPlusEqualsTheEnvelopeInEveryLaneOrGivesUp) {
  check_windowed_lanes<Lanes>();
}

TEST(LineTransforms, TheWindowedMinPlusInPlainLoopsDoesToo) {
  check_windowed_lanes<ScalarLanes>();
}

template <class L>
void check_windowed_bounds() {
  // Costs up to the 32-bit kernel's "no site" and lines of 4096: squared distances above 2^24,
  // where the float root of the window's reach rounds. Costs of kInf or more read kInf.
  std::mt19937 rng(5);
  const int n = 4096;
  std::vector<std::vector<std::int32_t>> lines(kWindowLanes, std::vector<std::int32_t>(n));
  for (int k = 0; k < kWindowLanes; ++k) {
    for (auto& v : lines[k]) {
      const std::uint32_t r = rng();
      v = r % (k + 2) == 0 ? kInf : static_cast<std::int32_t>(r % static_cast<std::uint32_t>(kInf));
    }
    if (k == 3) std::fill(lines[k].begin(), lines[k].end(), kInf);  // no site at all
    if (k == 5) {  // one site far from most of the line: distances up to 4095
      std::fill(lines[k].begin(), lines[k].end(), kInf);
      lines[k][0] = 7;
    }
  }
  std::vector<std::int32_t> f(static_cast<std::size_t>(n) * kWindowLanes), out(f.size());
  for (int k = 0; k < kWindowLanes; ++k)
    for (int x = 0; x < n; ++x) f[static_cast<std::size_t>(x) * kWindowLanes + k] = lines[k][x];
  ASSERT_TRUE(window_min_plus_lanes<L>(n, f.data(), kWindowLanes, out.data(), kWindowLanes,
                                       std::int64_t{1} << 40));
  for (int k = 0; k < kWindowLanes; ++k) {
    const LineResult ref = division_free(lines[k]);
    for (int x = 0; x < n; ++x)
      ASSERT_EQ(out[static_cast<std::size_t>(x) * kWindowLanes + k], std::min(ref.out[x], kInf))
          << "lane " << k << ", x " << x;
  }
}

TEST(LineTransforms, TheWindowedMinPlusHoldsAtTheThirtyTwoBitBounds) {
  check_windowed_bounds<Lanes>();
  check_windowed_bounds<ScalarLanes>();
}

TEST(LineTransforms, WindowedLinesGoToTheEnvelopeWhenTheirWindowsOutgrowTheBudget) {
  // 2W + 5 lines of 300 (two groups of W = kWindowLanes and five left over), interleaved: lines
  // near a site everywhere (cheap windows) and lines with one site at an end (windows of up to
  // 600 steps). With a budget of 16 steps per voxel the cheap group is solved by windows, the wide
  // one and the five left over by the envelope; every line equals the envelope's result.
  constexpr int W = kWindowLanes;
  const int n = 300, count = 2 * W + 5;
  std::mt19937 rng(31);
  std::vector<std::vector<std::int32_t>> lines(count, std::vector<std::int32_t>(n, kInf));
  for (int l = 0; l < count; ++l) {
    if (l >= W && l < 2 * W) {
      lines[l][l % 2 ? 0 : n - 1] = static_cast<std::int32_t>(rng() % 30);
    } else {
      for (int x = 0; x < n; ++x)
        if (rng() % 3 == 0) lines[l][x] = static_cast<std::int32_t>(rng() % 5);
      lines[l][0] = 1;
    }
  }
  std::vector<std::int32_t> f(static_cast<std::size_t>(n) * count), out(f.size(), -1);
  for (int l = 0; l < count; ++l)
    for (int x = 0; x < n; ++x) f[static_cast<std::size_t>(x) * count + l] = lines[l][x];
  std::vector<std::int32_t> scratch_in(kWindowLanes * n), scratch_out(kWindowLanes * n);
  std::vector<int> envelope_lines;
  const auto envelope = [&](int lines_in, int len, const std::int32_t* in, std::int32_t* o) {
    envelope_lines.push_back(lines_in);
    for (int l = 0; l < lines_in; ++l) {
      const std::vector<std::int32_t> line(in + static_cast<std::size_t>(l) * len,
                                           in + static_cast<std::size_t>(l + 1) * len);
      const LineResult r = division_free(line);
      std::copy(r.out.begin(), r.out.end(), o + static_cast<std::size_t>(l) * len);
    }
  };
  window_lines_or_envelope(count, n, f.data(), count, out.data(), 16, scratch_in.data(),
                           scratch_out.data(), envelope);
  EXPECT_EQ(envelope_lines, (std::vector<int>{W, 5}));  // the wide group, then the five left over
  for (int l = 0; l < count; ++l) {
    const LineResult ref = division_free(lines[l]);
    for (int x = 0; x < n; ++x)
      ASSERT_EQ(out[static_cast<std::size_t>(x) * count + l], ref.out[x])
          << "line " << l << ", x " << x;
  }
}

TEST(LineTransforms, TheLockStepEnvelopeHoldsAtTheThirtyTwoBitBounds) {
  std::mt19937 rng(11);
  const int n = 23170;  // n^2 < 2^29
  std::vector<std::vector<std::int32_t>> lines(4, std::vector<std::int32_t>(n));
  for (int k = 0; k < 4; ++k) {
    for (auto& v : lines[k]) {
      const std::uint32_t r = rng();
      v = r % (k + 2) == 0 ? kInf : static_cast<std::int32_t>(r % static_cast<std::uint32_t>(kInf));
    }
    lines[k][k == 0 ? n - 1 : 0] = kInf - 1;
  }
  const std::vector<LineResult> got = four_lanes(lines, true);
  for (int k = 0; k < 4; ++k) {
    const LineResult ref = meijster(lines[k]);
    EXPECT_EQ(got[k].out, ref.out) << "lane " << k;
    EXPECT_EQ(got[k].arg, ref.arg) << "lane " << k;
  }
}

// The local passes' truncated min-convolution (src/distance/truncated_min_convolution.h) against
// the definition: the least f(x', y') + (x - x')² + (y - y')² over the whole slice, "none" above
// the squared clamp. Random slices with sparse and dense sites, windows touching the slice's
// edges and not, widths that are and are not whole vectors, reaches up to the largest allowed.
TEST(TruncatedMinConvolution, EqualsTheClampedTwoDimensionalTransform) {
  using Conv = TruncatedMinConvolution;
  std::mt19937 rng(2012);
  Conv conv;
  int checked = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int nx = 1 + static_cast<int>(rng() % 90), ny = 1 + static_cast<int>(rng() % 90);
    const int mx = 1 + static_cast<int>(rng() % nx), my = 1 + static_cast<int>(rng() % ny);
    const int ox = static_cast<int>(rng() % (nx - mx + 1)),
              oy = static_cast<int>(rng() % (ny - my + 1));
    const int reaches[] = {1, 3, 16, 33, Conv::kMaxReach};
    const int reach = reaches[trial % 5];
    const double clamp = reach + (trial % 2 ? 0.5 : 0.0);
    const auto drop = static_cast<Conv::Cost>(std::floor(clamp * clamp));
    const double density = trial % 3 == 0 ? 0.002 : trial % 3 == 1 ? 0.05 : 0.6;
    std::vector<int> f(static_cast<std::size_t>(nx) * ny);
    for (int& v : f) {
      // Column costs as the z pass leaves them: squares of 0..reach, or none.
      const bool site = std::uniform_real_distribution<double>(0, 1)(rng) < density;
      const int dz = static_cast<int>(rng() % (reach + 1));
      v = site ? dz * dz : -1;
    }
    conv.prepare(nx, ny, ox, oy, mx, my, reach, drop);
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        const int v = f[static_cast<std::size_t>(y) * nx + x];
        conv.f_row(y)[x] = v < 0 ? Conv::kInf : static_cast<Conv::Cost>(v);
      }
    conv.solve();
    for (int j = 0; j < my; ++j)
      for (int i = 0; i < mx; ++i) {
        long best = -1;
        for (int y = 0; y < ny; ++y)
          for (int x = 0; x < nx; ++x) {
            const int v = f[static_cast<std::size_t>(y) * nx + x];
            if (v < 0) continue;
            const long c = v + static_cast<long>(x - (ox + i)) * (x - (ox + i)) +
                           static_cast<long>(y - (oy + j)) * (y - (oy + j));
            if (best < 0 || c < best) best = c;
          }
        const long expected = best < 0 || best > drop ? Conv::kInf : best;
        ASSERT_EQ(conv.out_row(j)[i], expected)
            << "trial " << trial << " at (" << ox + i << ", " << oy + j << ")";
        ++checked;
      }
  }
  EXPECT_GT(checked, 20000);
}
