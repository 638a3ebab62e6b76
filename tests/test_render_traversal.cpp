// The traversal's pieces against independent formulations: the Manhattan skip's caps hand the
// voxels left after rounding down to the axes of largest remainder (ties to the lower axis),
// written here as a stable sort of the axes, the way the rule reads.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "render/traverse.h"

using namespace voxfield;
using namespace voxfield::render_detail;

namespace {

// The caps of a Manhattan skip of stored distance `stored`: r = stored - 1 voxels shared over the
// axes in proportion to the direction's weights, each share rounded down, the voxels left given
// one each to the axes of largest remainder (ties to the lower axis; axes the ray does not move
// along come last).
std::array<int, 3> reference_caps(const SkipWeights& sw, int stored) {
  const int r = stored > 0 ? stored - 1 : 0;
  std::array<int, 3> caps{};
  std::array<double, 3> rest{};
  int used = 0;
  for (int a = 0; a < 3; ++a) {
    const double share = r * sw.w[a];
    caps[a] = static_cast<int>(share);
    rest[a] = sw.w[a] > 0 ? share - caps[a] : -1;
    used += caps[a];
  }
  std::array<int, 3> order{0, 1, 2};
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return rest[a] > rest[b]; });
  for (int k = 0; k < r - used && k < 3; ++k) ++caps[order[k]];
  return caps;
}

}  // namespace

TEST(RenderTraversal, ManhattanCapsGoToTheLargestRemainders) {
  SkipSource skip;
  skip.metric = Metric::kManhattan;
  std::vector<Vec3d> directions = {{1, 0, 0},  {0, 1, 0},  {0, 0, -1}, {1, 1, 0},  {1, 1, 1},
                                   {-1, 2, 0}, {3, -3, 3}, {1, 2, 3},  {0, -5, 5}, {2, 2, 1}};
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> unit(-1, 1);
  std::uniform_int_distribution<int> small(-4, 4);
  for (int i = 0; i < 3000; ++i) directions.push_back({unit(rng), unit(rng), unit(rng)});
  for (int i = 0; i < 1000; ++i) directions.push_back({1.0 * small(rng), 1.0 * small(rng), 1.0});
  int with_leftover = 0;
  for (const Vec3d& d : directions) {
    const SkipWeights sw(Metric::kManhattan, Ray{{0, 0, 0}, d});
    for (int stored = 0; stored <= 255; ++stored) {
      int caps[3];
      skip_caps(skip, sw, static_cast<std::uint8_t>(stored), caps);
      const std::array<int, 3> want = reference_caps(sw, stored);
      ASSERT_EQ(caps[0], want[0]) << "stored " << stored;
      ASSERT_EQ(caps[1], want[1]) << "stored " << stored;
      ASSERT_EQ(caps[2], want[2]) << "stored " << stored;
      // All of r is used: the box reaches as far as the L1 ball allows, and no farther.
      EXPECT_EQ(caps[0] + caps[1] + caps[2], stored > 0 ? stored - 1 : 0);
      int floors = 0;
      for (int a = 0; a < 3; ++a)
        floors += static_cast<int>((stored > 0 ? stored - 1 : 0) * sw.w[a]);
      with_leftover += floors < caps[0] + caps[1] + caps[2];
    }
  }
  EXPECT_GT(with_leftover, 100000);  // the leftover rule is what was tested, not only the floors
}
