// voxfield — the unit-spacing Euclidean lower envelope on several lines in lock-step, without
// data-dependent branches (internal).
//
// The kernel is Felzenszwalb & Huttenlocher's scan ("Distance transforms of sampled functions",
// 2012) in the division-free form of envelope_euclidean_int32 (line_transforms.h), which it
// matches value for value and site for site. That scan spends most of its time in mispredicted
// branches: whether the stack's top is popped for the next site, and whether the write-back moves
// to the next parabola, depend on the data, and on real volumes they go either way about as often
// (the profile of a 256³ transform: ~7 ns per line element, most of it in those two loops).
// Written as a state machine, each step does one of "pop the top" or "take the next site"
// (pushing it) and the write-back one of "move to the next parabola" or "emit this voxel", chosen
// by selects rather than branches; several lines run side by side so that one line's chain of
// dependent loads overlaps the others'. Steps per line: its sites plus the pops (at most as many)
// to build, n plus the stack's length to write back; sites of cost 0 that sit between two others
// are not built at all (below).
#pragma once

#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "line_transforms.h"

namespace voxfield::detail {

// Scratch entries per line for envelope_euclidean_int32_lanes: two below the stack (read, never
// used, while the stack holds fewer than two parabolas) and one above its largest size.
inline std::size_t envelope_lane_stride(int n) {
  return static_cast<std::size_t>(n) + 3;
}

// kLanes lines of n voxels: lane k reads f[k] and writes out[k] (and arg[k] when arg is not null:
// the smallest minimising index). Every line must hold at least one site (a cost below
// EuclideanInt32::kInf). s and h: kLanes * envelope_lane_stride(n) entries each.
template <int kLanes>
void envelope_euclidean_int32_lanes(int n, const std::int32_t* const* f, std::int32_t* const* out,
                                    std::int32_t* const* arg, std::int32_t* s, std::int32_t* h) {
  constexpr std::int32_t kInf = EuclideanInt32::kInf;
  const std::size_t stride = envelope_lane_stride(n);
  std::int32_t* S[kLanes];  // S[k][i], H[k][i]: the i-th parabola of lane k's stack (i >= -2)
  std::int32_t* H[kLanes];
  int i[kLanes], m[kLanes], q[kLanes];  // next site, sites, top of the stack (-1: empty)
  bool left_out = false;                // whether any lane left a run's inside out
  for (int k = 0; k < kLanes; ++k) {
    S[k] = s + k * stride + 2;
    H[k] = h + k * stride + 2;
    S[k][-2] = S[k][-1] = H[k][-2] = H[k][-1] = 0;
    // The voxels holding sites, listed first (in out[k], which the write-back overwrites later):
    // voxels without one would cost the build a step each, and sparse lines are mostly those.
    // Sites of cost 0 inside a run of them are left out too (costs are never negative): such a
    // voxel is its own nearest site, and beyond the run the run's end is strictly nearer at the
    // same cost, so it never minimises elsewhere (the write-back gives it its 0 itself). In real
    // volumes these are the voxels inside solid matter, often most of a line.
    int count = 0, runs = 0;
    bool zero_before = false, zero_here = n > 0 && f[k][0] == 0;
    for (int x = 0; x < n; ++x) {
      const bool zero_after = x + 1 < n && f[k][x + 1] == 0;
      const bool inside_run = zero_before & zero_here & zero_after;
      out[k][count] = x;
      count += static_cast<int>((f[k][x] < kInf) & !inside_run);
      runs += static_cast<int>(inside_run);
      zero_before = zero_here;
      zero_here = zero_after;
    }
    left_out |= runs > 0;
    m[k] = count;
    i[k] = 0;
    q[k] = -1;
  }
  // Build. A step on the next site u: pop the top when its stretch closes before u's opens
  // (X(p, u) <= X(a, p), cross-multiplied), or else push u and move on. u is written above the
  // top either way: that slot is free unless u is pushed.
  for (bool busy = true; busy;) {
    busy = false;
    for (int k = 0; k < kLanes; ++k) {
      const int ik = i[k];
      if (ik >= m[k]) continue;
      busy = true;
      const std::int64_t uk = out[k][ik];
      const std::int64_t hu = uk * uk + f[k][uk];
      const int qk = q[k];
      const std::int64_t a = S[k][qk - 1], ha = H[k][qk - 1], p = S[k][qk], hp = H[k][qk];
      const bool pop = (qk >= 1) & ((hu - hp) * (p - a) <= (hp - ha) * (uk - p));
      S[k][qk + 1] = static_cast<std::int32_t>(uk);
      H[k][qk + 1] = static_cast<std::int32_t>(hu);
      q[k] = qk + (pop ? -1 : 1);
      i[k] = ik + static_cast<int>(!pop);
    }
  }
  // Write back. A step on voxel x: move to the next parabola while it is strictly lower at x;
  // otherwise emit x from the current one. Every step stores x's value from the current parabola
  // (x^2 - 2 s x + h, its cost), and a later step at the same x overwrites it until the right
  // parabola is reached. The slot above the top repeats the top, so reading it is harmless.
  int x[kLanes], j[kLanes];
  for (int k = 0; k < kLanes; ++k) {
    S[k][q[k] + 1] = S[k][q[k]];
    H[k][q[k] + 1] = H[k][q[k]];
    x[k] = 0;
    j[k] = 0;
  }
  // Voxels of a left-out run take their own 0; without any (lines of no solid matter, where the
  // extra test would only cost) the plain write-back runs.
  const auto write_back = [&](auto runs_left_out) {
    for (bool busy = true; busy;) {
      busy = false;
      for (int k = 0; k < kLanes; ++k) {
        const int xk = x[k];
        if (xk >= n) continue;
        busy = true;
        const int jk = j[k];
        const std::int64_t s0 = S[k][jk], s1 = S[k][jk + 1], h0 = H[k][jk], h1 = H[k][jk + 1];
        const bool next = (jk < q[k]) & (2 * (s1 - s0) * xk > h1 - h0);
        auto value = static_cast<std::int32_t>(std::int64_t{xk} * xk - 2 * s0 * xk + h0);
        auto site = static_cast<std::int32_t>(s0);
        if constexpr (decltype(runs_left_out)::value) {
          const bool own_site = f[k][xk] == 0;  // cost 0 here: x is its own nearest site
          value = own_site ? 0 : value;
          site = own_site ? xk : site;
        }
        out[k][xk] = value;
        if (arg != nullptr) arg[k][xk] = site;
        j[k] = jk + static_cast<int>(next);
        x[k] = xk + static_cast<int>(!next);
      }
    }
  };
  if (left_out) {
    write_back(std::true_type{});
  } else {
    write_back(std::false_type{});
  }
}

}  // namespace voxfield::detail
