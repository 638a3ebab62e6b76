// Test helper: a world's voxels over a box as one dense array (x fastest), for comparing worlds
// voxel by voxel.
#pragma once

#include <cstdint>
#include <vector>

#include "voxfield/world.h"

namespace voxfield::test {

inline std::vector<std::uint8_t> dense_voxels(const World& w, const Box3i& box) {
  std::vector<std::uint8_t> v(static_cast<std::size_t>(box.volume()));
  w.voxels.copy_to_dense(box, v.data());
  return v;
}

}  // namespace voxfield::test
