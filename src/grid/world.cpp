// voxfield — World helpers and MagicaVoxel's default palette.
#include "voxfield/world.h"

#include <mutex>

namespace voxfield {

Palette default_palette() {
  Palette p{};  // entry 0: transparent black (air)
  int i = 1;
  static constexpr std::uint8_t kCube[6] = {0xFF, 0xCC, 0x99, 0x66, 0x33, 0x00};
  for (std::uint8_t r : kCube)
    for (std::uint8_t g : kCube)
      for (std::uint8_t b : kCube) {
        if (r == 0 && g == 0 && b == 0) continue;  // black is not in the cube
        p[i++] = {r, g, b, 0xFF};
      }
  static constexpr std::uint8_t kRamp[10] = {0xEE, 0xDD, 0xBB, 0xAA, 0x88,
                                             0x77, 0x55, 0x44, 0x22, 0x11};
  for (std::uint8_t v : kRamp) p[i++] = {v, 0, 0, 0xFF};
  for (std::uint8_t v : kRamp) p[i++] = {0, v, 0, 0xFF};
  for (std::uint8_t v : kRamp) p[i++] = {0, 0, v, 0xFF};
  for (std::uint8_t v : kRamp) p[i++] = {v, v, v, 0xFF};
  return p;  // i == 256 here: 215 cube entries + 40 ramp entries + air
}

std::array<std::int64_t, 256> World::material_histogram() const {
  std::array<std::int64_t, 256> total{};
  std::mutex merge;
  const std::int64_t n = voxels.chunk_volume();
  voxels.parallel_for_each_chunk([&](const ChunkView<std::uint8_t>& c) {
    std::array<std::int64_t, 256> local{};
    if (c.uniform()) {
      local[c.uniform_value] += n;
    } else {
      for (std::int64_t i = 0; i < n; ++i) ++local[c.voxels[i]];
    }
    std::lock_guard lock(merge);
    for (int m = 0; m < 256; ++m) total[m] += local[m];
  });
  return total;
}

}  // namespace voxfield
