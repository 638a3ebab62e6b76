// voxfield — the placement transform of MagicaVoxel scene graphs (internal to the .vox reader).
//
// Composed down the nTRN chain in exact integer arithmetic, so that placement never rounds.
#pragma once

#include <array>
#include <cstdint>

namespace voxfield::detail {

// A proper rotation or reflection of the axes, as MagicaVoxel stores it in one byte: bits 0-1 give
// the column of the non-zero entry of row 0, bits 2-3 that of row 1 (row 2 takes the remaining
// column) and bits 4, 5, 6 make rows 0, 1, 2 negative.
struct Affine {
  std::array<std::array<int, 3>, 3> r{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  std::array<std::int64_t, 3> t{0, 0, 0};

  Affine then_child(const Affine& c) const {  // this * c
    Affine out;
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) {
        int s = 0;
        for (int k = 0; k < 3; ++k) s += r[i][k] * c.r[k][j];
        out.r[i][j] = s;
      }
      std::int64_t s = t[i];
      for (int k = 0; k < 3; ++k) s += r[i][k] * c.t[k];
      out.t[i] = s;
    }
    return out;
  }
  // floor(T + R * (v - pivot + 0.5)) computed exactly in integers: with q = 2(v - pivot) + 1 (odd),
  // R q is odd on every axis and the floor of (R q) / 2 is an arithmetic shift.
  std::array<std::int64_t, 3> place(const std::array<std::int64_t, 3>& v,
                                    const std::array<std::int64_t, 3>& pivot) const {
    std::array<std::int64_t, 3> q{}, out{};
    for (int k = 0; k < 3; ++k) q[k] = 2 * (v[k] - pivot[k]) + 1;
    for (int i = 0; i < 3; ++i) {
      std::int64_t s = 0;
      for (int k = 0; k < 3; ++k) s += r[i][k] * q[k];
      out[i] = t[i] + (s >> 1);
    }
    return out;
  }
};

}  // namespace voxfield::detail
