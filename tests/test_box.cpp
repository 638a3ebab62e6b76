#include <gtest/gtest.h>

#include "voxfield/box.h"

using namespace voxfield;

TEST(Box, HalfOpenSemantics) {
  const Box3i b{{-2, 0, 5}, {3, 1, 7}};
  EXPECT_EQ(b.size(), (Vec3i{5, 1, 2}));
  EXPECT_EQ(b.volume(), 10);
  EXPECT_TRUE(b.contains(Vec3i{-2, 0, 5}));
  EXPECT_FALSE(b.contains(Vec3i{3, 0, 5}));
  EXPECT_FALSE(b.contains(Vec3i{0, 1, 5}));
  EXPECT_TRUE(Box3i::from_inclusive({0, 0, 0}, {0, 0, 0}).contains(Vec3i{0, 0, 0}));
  EXPECT_EQ(Box3i::from_inclusive({0, 0, 0}, {0, 0, 0}).volume(), 1);
}

TEST(Box, EmptyBoxesHaveZeroSizeAndUniteAway) {
  const Box3i e{{5, 5, 5}, {4, 9, 9}};
  EXPECT_TRUE(e.empty());
  EXPECT_EQ(e.volume(), 0);
  EXPECT_EQ(e.size(), (Vec3i{0, 4, 4}));
  const Box3i b{{0, 0, 0}, {2, 2, 2}};
  EXPECT_EQ(b.unite(e), b);
  EXPECT_EQ(e.unite(b), b);
  EXPECT_TRUE(b.contains(e));
}

TEST(Box, IntersectUniteGrow) {
  const Box3i a{{0, 0, 0}, {10, 10, 10}}, b{{5, -5, 8}, {20, 3, 9}};
  EXPECT_EQ(a.intersect(b), (Box3i{{5, 0, 8}, {10, 3, 9}}));
  EXPECT_EQ(a.unite(b), (Box3i{{0, -5, 0}, {20, 10, 10}}));
  EXPECT_EQ(a.grown(2), (Box3i{{-2, -2, -2}, {12, 12, 12}}));
  EXPECT_TRUE(a.intersect(Box3i{{10, 0, 0}, {11, 1, 1}}).empty());
}

TEST(Box, VolumeDoesNotOverflow) {
  const Box3i big{{-1000000, -1000000, -1000000}, {1000000, 1000000, 1000000}};
  EXPECT_EQ(big.volume(), std::int64_t{2000000} * 2000000 * 2000000);
}
