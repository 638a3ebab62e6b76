// The voxel-to-world frame: its map and inverse, normals under anisotropic scale, matrices read
// back as frames, and the refusals — checked against the map written out by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "backends.h"
#include "voxfield/algorithms.h"
#include "voxfield/error.h"
#include "voxfield/vectors.h"
#include "voxfield/voxel_frame.h"

using namespace voxfield;

namespace {

VoxelFrame sample_frame() {
  VoxelFrame f;
  f.origin_world = {10, -20, 0.5};
  f.voxel_size_world = {0.5, 2, 0.25};
  f.rotation = VectorVolume::rotation_about(35, {0.2, -1, 0.7});
  return f;
}

double distance(Vec3d a, Vec3d b) {
  return (a - b).length();
}

}  // namespace

TEST(VoxelFrame, TheIdentityMakesWorldCoordinatesVoxelCoordinates) {
  const VoxelFrame f;
  EXPECT_TRUE(f.is_identity());
  EXPECT_TRUE(f.axis_aligned());
  EXPECT_EQ(f.world_from_vox({1.5, -2, 7}), (Vec3d{1.5, -2, 7}));
  EXPECT_EQ(f.voxel_centre_world({3, 4, -5}), (Vec3d{3.5, 4.5, -4.5}));
  EXPECT_NO_THROW(f.validate("identity"));
}

TEST(VoxelFrame, MapsVoxelsByHandAndBack) {
  const VoxelFrame f = sample_frame();
  // By hand: origin + sum over axes of column a of R times size[a] * p[a].
  const Vec3d p{3.25, -1.5, 12};
  Vec3d want = f.origin_world;
  for (int a = 0; a < 3; ++a) {
    const Vec3d column{f.rotation[0][a], f.rotation[1][a], f.rotation[2][a]};
    want = want + column * (f.voxel_size_world[a] * p[a]);
  }
  EXPECT_LT(distance(f.world_from_vox(p), want), 1e-12);
  EXPECT_LT(distance(f.vox_from_world(f.world_from_vox(p)), p), 1e-12);
  // The matrix says the same.
  const auto m = f.world_from_vox_matrix();
  const Vec3d via_matrix{m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3],
                         m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
                         m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
  EXPECT_LT(distance(via_matrix, want), 1e-12);
  // Neighbouring voxel centres are one voxel edge apart along each axis.
  const Vec3i v{2, 3, 4};
  EXPECT_NEAR(distance(f.voxel_centre_world(v), f.voxel_centre_world(v + Vec3i{1, 0, 0})), 0.5,
              1e-12);
  EXPECT_NEAR(distance(f.voxel_centre_world(v), f.voxel_centre_world(v + Vec3i{0, 1, 0})), 2,
              1e-12);
  EXPECT_NEAR(distance(f.voxel_centre_world(v), f.voxel_centre_world(v + Vec3i{0, 0, 1})), 0.25,
              1e-12);
}

// A plane in voxel coordinates keeps its normal perpendicular to its image under a sheared-looking
// (anisotropic, rotated) map: the inverse transpose, not the map itself.
TEST(VoxelFrame, NormalsStayPerpendicularToTheirSurfaces) {
  const VoxelFrame f = sample_frame();
  const Vec3d n_vox = Vec3d{1, 2, -0.5}.normalized();
  const Vec3d t1 = cross(n_vox, Vec3d{0, 0, 1}), t2 = cross(n_vox, t1);  // in the plane
  const Vec3d n = f.world_normal(n_vox);
  EXPECT_NEAR(n.length(), 1, 1e-12);
  EXPECT_NEAR(dot(n, f.world_direction(t1)), 0, 1e-12);
  EXPECT_NEAR(dot(n, f.world_direction(t2)), 0, 1e-12);
  EXPECT_GT(dot(n, f.world_direction(n_vox)), 0);  // and still on the same side
  EXPECT_EQ(f.world_normal({0, 0, 0}), (Vec3d{0, 0, 0}));
}

TEST(VoxelFrame, MatricesBecomeFramesAndShearsAreRefused) {
  const VoxelFrame f = sample_frame();
  const VoxelFrame back = VoxelFrame::from_matrix(f.world_from_vox_matrix(), "m");
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(back.origin_world[a], f.origin_world[a], 1e-12);
    EXPECT_NEAR(back.voxel_size_world[a], f.voxel_size_world[a], 1e-12);
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(back.rotation[a][b], f.rotation[a][b], 1e-12);
  }
  // A rotation stored in floats (to ~1e-7) is taken, made exactly orthonormal.
  std::array<double, 12> rounded = f.world_from_vox_matrix();
  for (double& v : rounded) v = static_cast<double>(static_cast<float>(v));
  const VoxelFrame from_floats = VoxelFrame::from_matrix(rounded, "floats");
  EXPECT_NO_THROW(from_floats.validate("floats"));
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) EXPECT_NEAR(from_floats.rotation[a][b], f.rotation[a][b], 1e-6);
  std::array<double, 12> shear{1, 0.5, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  EXPECT_THROW((void)VoxelFrame::from_matrix(shear, "shear"), InvalidArgument);
  std::array<double, 12> mirror{-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  EXPECT_THROW((void)VoxelFrame::from_matrix(mirror, "mirror"), InvalidArgument);
  std::array<double, 12> flat{1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0};
  EXPECT_THROW((void)VoxelFrame::from_matrix(flat, "flat"), InvalidArgument);
}

TEST(VoxelFrame, InvalidFramesAreRefusedByName) {
  auto refused = [](VoxelFrame f) {
    try {
      f.validate("the test's frame");
    } catch (const InvalidArgument& e) {
      return std::string(e.what()).find("the test's frame") != std::string::npos;
    }
    return false;
  };
  VoxelFrame f;
  f.origin_world.y = std::nan("");
  EXPECT_TRUE(refused(f));
  f = {};
  f.voxel_size_world.z = 0;
  EXPECT_TRUE(refused(f));
  f.voxel_size_world.z = INFINITY;
  EXPECT_TRUE(refused(f));
  f = {};
  f.rotation[1] = {0, 1.001, 0};
  EXPECT_TRUE(refused(f));
  f = {};
  f.rotation[2] = {0, 0, -1};  // a mirror
  EXPECT_TRUE(refused(f));
  EXPECT_FALSE(refused(sample_frame()));
  EXPECT_NE(describe(sample_frame()).find("voxel size (0.5, 2, 0.25)"), std::string::npos)
      << describe(sample_frame());
}

// Every field computed from a world carries its frame, on each backend: the exact transform, the
// algorithm family, and the incremental field before and after an update.
class FieldFrameOn : public ::testing::TestWithParam<Backend> {};
INSTANTIATE_TEST_SUITE_P(Backends, FieldFrameOn, ::testing::Values(Backend::kCpu, Backend::kVulkan),
                         testing_backends::backend_test_name);

TEST_P(FieldFrameOn, FieldsCarryTheirWorldsFrame) {
  const Backend b = GetParam();
  VOXFIELD_SKIP_UNLESS_BACKEND(b);
  World w(16, Box3i::from_size({24, 20, 18}));
  w.voxels.fill({{5, 5, 5}, {9, 12, 10}}, 3);
  w.frame = sample_frame();
  DistanceOptions o;
  o.max_distance = 6;
  EXPECT_EQ(testing_backends::exact_field(b, w, o).frame, w.frame);
  AlgorithmOptions jfa;
  jfa.algorithm = Algorithm::kJfa;
  const DistanceField family = compute_distance_field(testing_backends::executor_of(b), w, o, jfa);
  EXPECT_EQ(family.frame, w.frame);
  IncrementalDistanceField live(testing_backends::executor_of(b), w, o);
  EXPECT_EQ(live.field().frame, w.frame);
  DirtyRegions dirty(16);
  w.voxels.set({15, 15, 15}, 2);
  dirty.add({{15, 15, 15}, {16, 16, 16}});
  live.update(dirty);
  EXPECT_EQ(live.field().frame, w.frame);
  testing_backends::expect_no_validation_messages(b);
}
