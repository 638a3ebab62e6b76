// Cameras given in a world's frame (Camera::in_voxels): the frame a user places in world
// coordinates is the frame placed in voxels by hand — the same camera, the same pixels — for
// frames of cubic voxels with any origin and rotation; for voxels that are not cubes, the view of
// the same scene built from cubes.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <string>

#include "image_compare.h"
#include "voxfield/csg.h"
#include "voxfield/csg_render.h"
#include "voxfield/error.h"
#include "voxfield/mesh_render.h"
#include "voxfield/render.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

// A world's frame: turned by `degrees` about `axis`, voxels of edge `size`, voxel (0, 0, 0) at
// `origin`.
VoxelFrame frame_of(double degrees, Vec3d axis, double size, Vec3d origin) {
  const double a = degrees * std::numbers::pi / 180, c = std::cos(a), s = std::sin(a);
  const Vec3d k = axis * (1 / axis.length());
  VoxelFrame f;
  f.origin_world = origin;
  f.voxel_size_world = {size, size, size};
  // Rodrigues' rotation matrix, row by row.
  f.rotation = {
      {{c + k.x * k.x * (1 - c), k.x * k.y * (1 - c) - k.z * s, k.x * k.z * (1 - c) + k.y * s},
       {k.y * k.x * (1 - c) + k.z * s, c + k.y * k.y * (1 - c), k.y * k.z * (1 - c) - k.x * s},
       {k.z * k.x * (1 - c) - k.y * s, k.z * k.y * (1 - c) + k.x * s, c + k.z * k.z * (1 - c)}}};
  return f;
}

// The camera `in_vox` as a user of `frame` writes it: in world coordinates.
Camera in_world(const Camera& in_vox, const VoxelFrame& frame) {
  Camera c = in_vox;
  c.eye = frame.world_from_vox(in_vox.eye);
  c.target = frame.world_from_vox(in_vox.target);
  c.up = frame.world_direction(in_vox.up);
  c.ortho_height = in_vox.ortho_height * frame.voxel_size_world.x;
  return c;
}

void expect_near(Vec3d a, Vec3d b, double tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance);
  EXPECT_NEAR(a.y, b.y, tolerance);
  EXPECT_NEAR(a.z, b.z, tolerance);
}

}  // namespace

// Exact frames (power-of-two voxel sizes, whole-number origins, no rotation) give the very camera
// and the very pixels; turned frames give the camera to within rounding and the same picture.
TEST(CameraFrame, AWorldCameraDrawsWhatTheSameCameraInVoxelsDraws) {
  SceneOptions so;
  so.size = {48, 40, 24};
  World world = make_terrain(so);
  Camera by_hand;
  by_hand.eye = {70, -30, 45};
  by_hand.target = {24, 20, 6};
  by_hand.up = {0, 0, 1};
  RenderOptions o;
  o.width = 160;
  o.height = 96;
  const RenderScene scene(world);
  const Image want = render(scene, by_hand, o);
  std::set<std::uint32_t> colours;  // terrain in view, not sky alone
  for (std::size_t i = 0; i + 2 < want.rgb.size(); i += 3)
    colours.insert(std::uint32_t{want.rgb[i]} << 16 | std::uint32_t{want.rgb[i + 1]} << 8 |
                   want.rgb[i + 2]);
  ASSERT_GT(colours.size(), 200u);
  for (const VoxelFrame& frame :
       {frame_of(0, {0, 0, 1}, 0.25, {100, -50, 3}), frame_of(0, {0, 0, 1}, 8, {-4, 0, 0})}) {
    const Camera c = in_world(by_hand, frame).in_voxels(frame);
    EXPECT_EQ(c.eye, by_hand.eye);
    EXPECT_EQ(c.target, by_hand.target);
    EXPECT_EQ(c.up, by_hand.up);
    const Image got = render(scene, c, o);
    EXPECT_TRUE(got.rgb == want.rgb);
  }
  for (const VoxelFrame& frame : {frame_of(90, {0, 0, 1}, 0.05, {12.5, 3, -7}),
                                  frame_of(33, {1, 2, -0.5}, 1.7, {1e4, -2e3, 350})}) {
    SCOPED_TRACE(frame.rotation[0].x);
    const Camera c = in_world(by_hand, frame).in_voxels(frame);
    expect_near(c.eye, by_hand.eye, 1e-9);
    expect_near(c.target, by_hand.target, 1e-9);
    expect_near(c.up * (1 / c.up.length()), by_hand.up, 1e-12);
    // Rays a part in 10^12 apart: a pixel may flip where a ray grazes an edge, no more.
    const test::ImageDiff d = test::compare_images(render(scene, c, o), want, 0);
    EXPECT_LE(d.off, d.pixels / 1000);
  }
}

// An orthographic camera's height is in world units: it shrinks by the voxel edge.
TEST(CameraFrame, OrthographicHeightsAreWorldUnits) {
  Camera c;
  c.projection = Camera::Projection::kOrthographic;
  c.eye = {0, 0, 10};
  c.target = {0, 0, 0};
  c.up = {0, 1, 0};
  c.ortho_height = 3;
  const Camera v = c.in_voxels(frame_of(0, {0, 0, 1}, 0.5, {0, 0, 0}));
  EXPECT_EQ(v.ortho_height, 6);
  EXPECT_EQ(v.eye, (Vec3d{0, 0, 20}));
  EXPECT_EQ(v.projection, Camera::Projection::kOrthographic);
}

// Voxels that are not cubes: a scan of 0.5 x 0.5 x 2 (moved, turned about z or tilted) drawn by a
// camera in its world is the view of the same scene built from cubes — each voxel four 0.5-cubes
// high — by the same world camera, perspective and orthographic. (Flat light: ambient occlusion
// and soft shadows measure distances in voxels, which the two worlds count differently.)
TEST(CameraFrame, AnisotropicVoxelsDrawTheWorldsView) {
  SceneOptions so;
  so.size = {48, 40, 12};
  const World terrain = make_terrain(so);
  RenderOptions o;
  o.width = 160;
  o.height = 96;
  o.ambient_occlusion = false;
  o.soft_shadows = false;
  for (const VoxelFrame& turn :
       {frame_of(30, {0, 0, 1}, 0.5, {7, -3, 2}), frame_of(25, {1, 2, -0.5}, 0.5, {-40, 9, 1})}) {
    SCOPED_TRACE(turn.rotation[0].z);
    World scan = terrain;
    scan.frame = turn;
    scan.frame.voxel_size_world = {0.5, 0.5, 2};
    World cubes(8, Box3i::from_size({so.size.x, so.size.y, 4 * so.size.z}));
    cubes.palette = scan.palette;
    cubes.frame = turn;
    for (int z = 0; z < so.size.z; ++z)
      for (int y = 0; y < so.size.y; ++y)
        for (int x = 0; x < so.size.x; ++x)
          if (const std::uint8_t m = scan.voxels.get({x, y, z}))
            for (int k = 0; k < 4; ++k) cubes.voxels.set({x, y, 4 * z + k}, m);
    World empty(8, cubes.voxels.bounds());  // the sky alone
    empty.frame = turn;
    const RenderScene scan_scene(scan), cubes_scene(cubes), sky_scene(empty);
    Camera c;
    c.eye = scan.frame.world_from_vox({56, -12, 14});
    c.target = scan.frame.world_from_vox({24, 20, 4});
    c.up = scan.frame.world_direction({0, 0, 1});
    Camera ortho = c;
    ortho.projection = Camera::Projection::kOrthographic;
    ortho.eye = scan.frame.world_from_vox({64, -20, 24});
    ortho.ortho_height = 30;
    for (const Camera& world_camera : {c, ortho}) {
      const char* what = &world_camera == &c ? "perspective" : "orthographic";
      const Camera in_scan = world_camera.in_voxels(scan.frame);
      ASSERT_TRUE(in_scan.world_frame.has_value());
      const Camera in_cubes = world_camera.in_voxels(cubes.frame);
      EXPECT_FALSE(in_cubes.world_frame.has_value());
      const Image want = render(cubes_scene, in_cubes, o), got = render(scan_scene, in_scan, o);
      // The terrain fills much of the picture, not the sky alone.
      const test::ImageDiff terrain_in_view =
          test::compare_images(want, render(sky_scene, in_cubes, o), 0);
      EXPECT_GT(terrain_in_view.off, terrain_in_view.pixels / 5) << what;
      // The two worlds' rays differ in rounding: a pixel may flip where a ray grazes an edge.
      const test::ImageDiff d = test::compare_images(got, want, 0);
      EXPECT_LE(d.off, d.pixels / 1000) << what;
      // The voxels' shape matters: drawn as cubes, the scan is another picture.
      VoxelFrame cubic = scan.frame;
      cubic.voxel_size_world = {0.5, 0.5, 0.5};
      const test::ImageDiff wrong =
          test::compare_images(render(scan_scene, world_camera.in_voxels(cubic), o), want, 0);
      EXPECT_GT(wrong.off, wrong.pixels / 20) << what;
    }
  }
}

// A mesh or a CSG model has no voxels to carry its rays into: their renderers refuse such a
// camera by name.
TEST(CameraFrame, MeshesRefuseACameraOfNonCubicVoxels) {
  VoxelFrame scan;
  scan.voxel_size_world = {1, 1, 3};
  const Camera c = Camera{}.in_voxels(scan);
  ASSERT_TRUE(c.world_frame.has_value());
  Mesh mesh;
  MeshRenderOptions o;
  o.width = 8;
  o.height = 8;
  try {
    (void)render_mesh(mesh, c, o);
    ADD_FAILURE() << "render_mesh drew through a camera of non-cubic voxels";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("non-cubic"), std::string::npos) << e.what();
  }
  try {
    (void)terrain_view(c, o);
    ADD_FAILURE() << "terrain_view took a camera of non-cubic voxels";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("non-cubic"), std::string::npos) << e.what();
  }
  // Nor does a CSG model, traced in its own units (the GPU's CSG renderer shares the check).
  CsgRenderOptions co;
  co.width = 8;
  co.height = 8;
  co.camera = c;
  EXPECT_THROW((void)render_csg(csg::parse_model_sexpr("(sphere 4)", "ball"), co), InvalidArgument);
  EXPECT_THROW((void)c.in_voxels(scan), InvalidArgument);  // placed once
}

TEST(CameraFrame, InvalidFramesAreRefusedAndNearCubesAreCubes) {
  Camera c;
  VoxelFrame bad;
  bad.voxel_size_world = {0, 0, 0};
  EXPECT_THROW((void)c.in_voxels(bad), InvalidArgument);
  // Sizes equal to a part in 10^6 are cubes (a float pipeline's rotated transform): a plain
  // camera in voxels; beyond, the camera keeps the frame.
  VoxelFrame nearly;
  nearly.voxel_size_world = {0.1, 0.1 * (1 + 1e-8), 0.1};
  EXPECT_FALSE(c.in_voxels(nearly).world_frame.has_value());
  nearly.voxel_size_world = {0.1, 0.1 * (1 + 1e-5), 0.1};
  EXPECT_TRUE(c.in_voxels(nearly).world_frame.has_value());
}

// Only a placed camera has a frame to be given in: "auto", "top" and an empty spec frame the box.
TEST(CameraFrame, FramingSpecsAreNotPlacedCameras) {
  EXPECT_TRUE(Camera::frames_the_box(""));
  EXPECT_TRUE(Camera::frames_the_box("auto"));
  EXPECT_TRUE(Camera::frames_the_box("top"));
  EXPECT_FALSE(Camera::frames_the_box("eye=1,2,3:target=0,0,0"));
}
