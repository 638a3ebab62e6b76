// voxfield — the reference dissertation's voxel format, for comparing with its renderer's data:
// one packed 32-bit word per voxel.
#pragma once

#include <cstdint>
#include <vector>

#include "voxfield/distance.h"

namespace voxfield {

// The dissertation's packed 32-bit voxel: bits 8-15 the Manhattan distance (0..255, clamped),
// bits 0-7 the voxel's palette colour as RGB332 (0 for air). Dense, x fastest, over `box`.
std::vector<std::uint32_t> pack_dissertation_format(const World& world, const DistanceField& field,
                                                    const Box3i& box);

}  // namespace voxfield
