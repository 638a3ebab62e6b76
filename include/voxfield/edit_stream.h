// voxfield — a reproducible stream of random edits: the reference dissertation's benchmark
// workload (`voxfield bench edits`, the demo's benchmark mode, the incremental-field tests).
#pragma once

#include <cstdint>
#include <random>

#include "voxfield/edit.h"

namespace voxfield {

// The reference dissertation's automated edits: sphere brushes centred anywhere in `box`, radii
// uniform in [radius_min, radius_max], materials uniform in 0..255 where 0 (air) carves and the
// rest place — the same stream for the same seed on every machine (`voxfield bench edits`, the
// demo's benchmark mode).
class RandomEditStream {
 public:
  // Throws InvalidArgument for an empty box or radii outside 0 <= min <= max.
  RandomEditStream(const Box3i& box, std::uint64_t seed, int radius_min, int radius_max);
  Edit next();

 private:
  int uniform(int lo, int hi);
  Box3i box_;
  std::mt19937_64
      rng_;  // specified bit for bit by the standard (the distributions are not: unused)
  int radius_min_, radius_max_;
};

}  // namespace voxfield
