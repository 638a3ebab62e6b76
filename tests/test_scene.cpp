// Generated scenes: deterministic, chunk-independent, with the advertised solid fractions.
#include <gtest/gtest.h>

#include "voxfield/parallel.h"
#include "voxfield/scene.h"
#include "world_voxels.h"

using namespace voxfield;

TEST(Scene, TerrainIsDeterministicAcrossChunkEdgesAndThreads) {
  SceneOptions o;
  o.size = {70, 53, 61};  // odd sizes, not multiples of any chunk edge
  const auto reference = test::dense_voxels(make_terrain(o), Box3i::from_size(o.size));
  for (int edge : {8, 16, 64, 128}) {
    o.chunk_edge = edge;
    EXPECT_EQ(test::dense_voxels(make_terrain(o), Box3i::from_size(o.size)), reference) << edge;
  }
  ThreadLimit one(1);
  o.chunk_edge = 32;
  EXPECT_EQ(test::dense_voxels(make_terrain(o), Box3i::from_size(o.size)), reference);
  o.seed = 1;
  EXPECT_NE(test::dense_voxels(make_terrain(o), Box3i::from_size(o.size)), reference);
}

TEST(Scene, SolidFractions) {
  SceneOptions o;
  o.size = {128, 128, 128};
  const World t = make_terrain(o);
  const double terrain = static_cast<double>(t.solid_count()) / Box3i::from_size(o.size).volume();
  EXPECT_GT(terrain, 0.35);
  EXPECT_LT(terrain, 0.65);
  const World s = make_spheres(o);
  const double spheres = static_cast<double>(s.solid_count()) / Box3i::from_size(o.size).volume();
  EXPECT_GT(spheres, 0.06);
  EXPECT_LT(spheres, 0.11);
  // Nothing outside the bounds.
  EXPECT_TRUE(Box3i::from_size(o.size).contains(t.voxels.content_bounds()));
  EXPECT_THROW(make_scene("mountains", o), InvalidArgument);
  o.size = {0, 5, 5};
  EXPECT_THROW(make_terrain(o), InvalidArgument);
  o.size = {65536, 65536,
            65536};  // 2.8e14 voxels: refused up front, not by the out-of-memory killer
  EXPECT_THROW(make_terrain(o), InvalidArgument);
  EXPECT_THROW(make_spheres(o), InvalidArgument);
}
