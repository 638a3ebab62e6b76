// Generated scenes: deterministic, chunk-independent, with the advertised solid fractions.
#include <gtest/gtest.h>

#include "voxfield/parallel.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

std::vector<std::uint8_t> dense(const World& w, Vec3i size) {
  std::vector<std::uint8_t> v(static_cast<std::size_t>(Box3i::from_size(size).volume()));
  w.voxels.copy_to_dense(Box3i::from_size(size), v.data());
  return v;
}

}  // namespace

TEST(Scene, TerrainIsDeterministicAcrossChunkEdgesAndThreads) {
  SceneOptions o;
  o.size = {70, 53, 61};  // odd sizes, not multiples of any chunk edge
  const auto reference = dense(make_terrain(o), o.size);
  for (int edge : {8, 16, 64, 128}) {
    o.chunk_edge = edge;
    EXPECT_EQ(dense(make_terrain(o), o.size), reference) << edge;
  }
  ThreadLimit one(1);
  o.chunk_edge = 32;
  EXPECT_EQ(dense(make_terrain(o), o.size), reference);
  o.seed = 1;
  EXPECT_NE(dense(make_terrain(o), o.size), reference);
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
