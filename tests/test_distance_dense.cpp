// compute_distance_field_into (include/voxfield/distance.h): the exact field written into a
// caller's dense array. Its values are held against brute force for every metric, sign, clamp and
// spacing beside the field's own in test_distance.cpp (check_case); here, what it refuses, the
// domain it covers and the values where no site is within reach.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/error.h"

using namespace voxfield;

TEST(DenseDistances, RefusesSitesNoArrayAndZeroStridesAndKeepsTheDomain) {
  World w(16, Box3i::from_size({9, 7, 5}));
  w.voxels.set({4, 3, 2}, 1);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  std::vector<float> out(9 * 7 * 5, -1.0f);
  const DenseDistances<float> dense{out.data(), {1, 9, 63}};
  o.nearest_sites = true;
  EXPECT_THROW(compute_distance_field_into(w.voxels, o, dense), InvalidArgument);
  o.nearest_sites = false;
  EXPECT_THROW(compute_distance_field_into(w.voxels, o, DenseDistances<float>{}), InvalidArgument);
  o.max_distance = -1;
  EXPECT_THROW(compute_distance_field_into(w.voxels, o, dense), InvalidArgument);
  o.max_distance = 0;
  EXPECT_THROW(
      compute_distance_field_into(w.voxels, o, DenseDistances<float>{out.data(), {1, 0, 63}}),
      InvalidArgument);
  // A grid without bounds and no domain: the caller could not know what the array covers.
  Grid<std::uint8_t> unbounded(16, 0);
  unbounded.set({3, 3, 3}, 1);
  EXPECT_THROW(compute_distance_field_into(unbounded, o, dense), InvalidArgument);
  EXPECT_EQ(out, std::vector<float>(out.size(), -1.0f)) << "a refused call wrote output";
  // A domain that is a part of the world: the array covers the domain, from its first voxel.
  o.max_distance = 0;
  o.domain = Box3i{{2, 1, 1}, {7, 6, 4}};
  std::vector<float> part(5 * 5 * 3, -1.0f);
  compute_distance_field_into(w.voxels, o, DenseDistances<float>{part.data(), {1, 5, 25}});
  for (int z = 0; z < 3; ++z)
    for (int y = 0; y < 5; ++y)
      for (int x = 0; x < 5; ++x) {
        const double dx = x + 2 - 4, dy = y + 1 - 3, dz = z + 1 - 2;
        EXPECT_FLOAT_EQ(part[x + 5 * y + 25 * z], std::sqrt(dx * dx + dy * dy + dz * dz));
      }
  // No site anywhere: +inf unclamped, the clamp otherwise.
  World empty(16, Box3i::from_size({4, 4, 4}));
  std::vector<double> none(64, 0.0);
  DistanceOptions e;
  e.metric = Metric::kEuclidean;
  compute_distance_field_into(empty.voxels, e, DenseDistances<double>{none.data(), {1, 4, 16}});
  for (double v : none) EXPECT_EQ(v, std::numeric_limits<double>::infinity());
  e.max_distance = 2.5;
  compute_distance_field_into(empty.voxels, e, DenseDistances<double>{none.data(), {1, 4, 16}});
  for (double v : none) EXPECT_EQ(v, 2.5);
}
