// voxfield — the reference dissertation's seeded stream of random sphere edits.
#include <string>

#include "voxfield/edit.h"
#include "voxfield/edit_stream.h"
#include "voxfield/error.h"

namespace voxfield {

RandomEditStream::RandomEditStream(const Box3i& box, std::uint64_t seed, int radius_min,
                                   int radius_max)
    : box_(box), rng_(seed), radius_min_(radius_min), radius_max_(radius_max) {
  if (box.empty()) throw InvalidArgument("edit stream: empty box " + to_string(box));
  if (radius_min < 0 || radius_max < radius_min)
    throw InvalidArgument("edit stream: need 0 <= radius_min <= radius_max (got " +
                          std::to_string(radius_min) + ", " + std::to_string(radius_max) + ")");
}

// Uniform in [lo, hi] by a remainder: the modulo bias is below 2^-40 for the ranges used here, and
// unlike std::uniform_int_distribution the result is the same on every standard library.
int RandomEditStream::uniform(int lo, int hi) {
  return lo + static_cast<int>(rng_() % static_cast<std::uint64_t>(hi - lo + 1));
}

Edit RandomEditStream::next() {
  // Draw order (radius, material, x, y, z) is part of the stream's definition.
  const int radius = uniform(radius_min_, radius_max_);
  const int material = uniform(0, 255);
  Edit e;
  const double x = uniform(box_.begin.x, box_.end.x - 1);
  const double y = uniform(box_.begin.y, box_.end.y - 1);
  const double z = uniform(box_.begin.z, box_.end.z - 1);
  e.brush = SphereBrush{{x, y, z}, static_cast<double>(radius)};
  e.op = material == 0 ? EditOp::kCarve : EditOp::kPlace;
  e.material = static_cast<std::uint8_t>(material == 0 ? 1 : material);
  return e;
}

}  // namespace voxfield
