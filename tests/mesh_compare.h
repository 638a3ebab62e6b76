// Test helper: a mesh's triangles independent of its vertex numbering — each triangle as its three
// corners' (position, normal[, colour]) bits (so -0 and +0 differ), rotated to start at the
// smallest corner (orientation kept), the list sorted. Two meshes with the same triangles give
// equal lists.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <vector>

#include "voxfield/mesh.h"

namespace voxfield::test {

using MeshCorner = std::array<std::uint32_t, 6>;

// kColors: each corner also carries its vertex colour (the mesh must have colours).
template <bool kColors = false>
std::vector<std::array<std::array<std::uint32_t, kColors ? 7 : 6>, 3>> corner_triangles(
    const Mesh& m) {
  std::vector<std::array<std::array<std::uint32_t, kColors ? 7 : 6>, 3>> out(m.triangle_count());
  for (std::size_t t = 0; t < out.size(); ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t v = m.indices[3 * t + k];
      for (std::size_t a = 0; a < 3; ++a) {
        out[t][k][a] = std::bit_cast<std::uint32_t>(m.positions[v][a]);
        out[t][k][3 + a] = std::bit_cast<std::uint32_t>(m.normals[v][a]);
      }
      if constexpr (kColors) {
        const auto& c = m.colors.at(v);
        out[t][k][6] = c[0] | c[1] << 8 | c[2] << 16;
      }
    }
    std::rotate(out[t].begin(), std::min_element(out[t].begin(), out[t].end()), out[t].end());
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace voxfield::test
