// The neighbours of one slab of a domain cut into z-slabs, as voxfield-mpi reduces them over its
// ranks: the nearest below is the highest of the slabs below, the nearest above the lowest of the
// slabs above (distance_slab.h). For the CPU's and the GPU's slab tests.
#pragma once

#include <algorithm>
#include <vector>

#include "voxfield/distance_slab.h"

namespace voxfield::test {

inline SlabNeighbours neighbours_of(const std::vector<ColumnSites>& all, std::size_t i) {
  const std::size_t n = all[i].lowest_solid.size();
  SlabNeighbours s;
  s.solid_below.assign(n, ColumnSites::kNoneHigh);
  s.air_below.assign(n, ColumnSites::kNoneHigh);
  s.solid_above.assign(n, ColumnSites::kNoneLow);
  s.air_above.assign(n, ColumnSites::kNoneLow);
  for (std::size_t j = 0; j < all.size(); ++j) {
    for (std::size_t c = 0; c < n; ++c) {
      if (j < i) {
        s.solid_below[c] = std::max(s.solid_below[c], all[j].highest_solid[c]);
        s.air_below[c] = std::max(s.air_below[c], all[j].highest_air[c]);
      } else if (j > i) {
        s.solid_above[c] = std::min(s.solid_above[c], all[j].lowest_solid[c]);
        s.air_above[c] = std::min(s.air_above[c], all[j].lowest_air[c]);
      }
    }
  }
  return s;
}

}  // namespace voxfield::test
