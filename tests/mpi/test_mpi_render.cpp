// Frames drawn where the world lies (mpi::render, render_relay.h) against one process: run under
// mpirun with 1..N ranks, every rank builds the same world, keeps its slab and ghost slices, and
// rank 0's frame must equal render() of the whole world's scene byte for byte — soft shadows cast
// across slabs, ambient occlusion at slab borders, skipping rays, fog, the chunks view and cameras
// from above, below and inside included, and the distance view's cuts; bad options must fail on
// every rank alike.
#include <gtest/gtest.h>
#include <mpi.h>

#include <random>
#include <string>

#include "mpi_ranks.h"
#include "voxfield/mpi.h"
#include "voxfield/render.h"
#include "voxfield/render_relay.h"

namespace voxfield {
namespace {

using test::comm;
using test::rank;
using test::ranks;

// Ground, pillars and floating blocks over 8 chunk layers along z, so that slabs of every rank
// count cast shadows on one another, with a sprinkle of single voxels.
World scene_world(std::uint32_t seed, const Box3i& domain, int edge) {
  std::mt19937 rng(seed);
  World w(edge, domain);
  const Vec3i lo = domain.begin, size = domain.size();
  w.voxels.fill({lo, {domain.end.x, domain.end.y, lo.z + 3}}, 1);
  const auto at = [&](int n) { return static_cast<int>(rng() % static_cast<unsigned>(n)); };
  for (int k = 0; k < 14; ++k) {
    const Vec3i a{lo.x + at(size.x - 6), lo.y + at(size.y - 6), lo.z + at(size.z - 8)};
    const Vec3i extent{2 + at(5), 2 + at(5), 2 + at(k % 3 ? 6 : size.z - (a.z - lo.z))};
    w.voxels.fill(Box3i{a, a + extent}.intersect(domain), static_cast<std::uint8_t>(2 + k % 5));
  }
  for (int k = 0; k < 150; ++k)
    w.voxels.set({lo.x + at(size.x), lo.y + at(size.y), lo.z + at(size.z)},
                 static_cast<std::uint8_t>(1 + at(7)));
  return w;
}

struct Case {
  std::string what;
  RenderSceneOptions scene;
  Camera camera;
  RenderOptions options;
};

void check(const Case& c, const World& whole, const Box3i& domain, int edge) {
  const mpi::SlabPartition p = mpi::partition_slabs(domain, ranks(), edge);
  const Box3i keep = relay_world_box(domain, p.slab(rank()), c.scene);
  World mine(edge, keep);
  mine.voxels = whole.voxels.rechunked(edge, keep);
  mine.palette = whole.palette;
  RenderStats stats;
  mpi::ExchangeStats exchange;
  const Image frame = mpi::render(comm(), p, mine, c.scene, c.camera, c.options, &stats, &exchange);
  // Every pixel's primary ray that enters the box is walked by one rank at least.
  std::int64_t walked = stats.primary.rays, all_walked = 0;
  MPI_Allreduce(&walked, &all_walked, 1, MPI_INT64_T, MPI_SUM, comm());
  EXPECT_GT(all_walked, 0) << c.what;
  if (rank() != 0) {
    EXPECT_TRUE(frame.rgb.empty()) << c.what;
    return;
  }
  const Image expect = render(RenderScene(whole, c.scene, domain), c.camera, c.options);
  ASSERT_EQ(frame.width, expect.width) << c.what;
  ASSERT_EQ(frame.height, expect.height) << c.what;
  std::size_t differ = 0;
  for (std::size_t i = 0; i < expect.rgb.size(); ++i) differ += frame.rgb[i] != expect.rgb[i];
  EXPECT_EQ(differ, 0u) << c.what << ": bytes that differ from one process's frame";
}

// 8 chunk layers of 8 along z; the first starts off a chunk boundary (at the domain's face).
const Box3i kSceneDomain{{-7, 5, -13}, {41, 45, 48}};

// A 96 x 64 frame (aspect 1.5) in the given view.
RenderOptions small_frame(RenderView view) {
  RenderOptions o;
  o.width = 96;
  o.height = 64;
  o.view = view;
  return o;
}

// One scene's frames to check: the scene world of `seed` over kSceneDomain in chunks of 8, and
// small_frame(view) for the cases to start from.
struct SceneFrames {
  int edge = 8;
  Box3i domain = kSceneDomain;
  World world;
  RenderOptions options;
  double aspect = 1.5;
  std::vector<Case> cases;

  SceneFrames(std::uint32_t seed, RenderView view)
      : world(scene_world(seed, kSceneDomain, 8)), options(small_frame(view)) {}
  void check_all() const {
    for (const Case& c : cases) check(c, world, domain, edge);
  }
};

TEST(MpiRender, FramesEqualOneProcessByteForByte) {
  SceneFrames s(17, RenderView::kShaded);
  s.cases.push_back({"shaded, framing camera", {}, Camera::framing(s.domain, s.aspect), s.options});
  s.cases.push_back(
      {"shaded, orthographic from above", {}, Camera::top(s.domain, s.aspect), s.options});
  Case low{"a low sun, from below the ground, fog",
           {},
           Camera::parse("eye=17,25,-40:target=17,25,10:up=0,1,0", s.domain, s.aspect),
           s.options};
  low.options.sun_direction = {0.9, 0.2, 0.15};
  low.options.fog_density = 0.01;
  s.cases.push_back(low);
  Case inside{"from inside, the sun below",
              {},
              Camera::parse("eye=30,12,20:target=0,40,0:fov=80", s.domain, s.aspect),
              s.options};
  inside.options.sun_direction = {-0.3, 0.4, -0.8};
  s.cases.push_back(inside);
  Case chunks{"the chunks view, Euclidean skip clamped at 12, no skipping for primary rays",
              {},
              Camera::framing(s.domain, s.aspect, 35),
              s.options};
  chunks.scene.skip_metric = Metric::kEuclidean;
  chunks.scene.skip_max_distance_vox = 12;
  chunks.scene.lighting_max_distance_vox = 9.5;
  chunks.options.view = RenderView::kChunks;
  chunks.options.skip = SkipMode::kNone;
  s.cases.push_back(chunks);
  Case flat{"Chebyshev skip, a sun on the horizon, orthographic from the side",
            {},
            Camera::parse("eye=17,-60,20:target=17,25,10:ortho=70", s.domain, s.aspect),
            s.options};
  flat.scene.skip_metric = Metric::kChebyshev;
  flat.options.sun_direction = {0.6, 0.8, 0};
  s.cases.push_back(flat);
  Case plain{"no lighting field", {}, Camera::framing(s.domain, s.aspect), s.options};
  plain.scene.lighting_field = false;
  plain.options.ambient_occlusion = false;
  plain.options.soft_shadows = false;
  plain.options.skip = SkipMode::kChunks;
  s.cases.push_back(plain);
  s.check_all();
}

// The distance view: rays walk the box below the cut plane, and those that enter it through the
// plane on air show the skip field there, drawn by the rank that holds the plane's slice.
TEST(MpiRender, DistanceViewsEqualOneProcessByteForByte) {
  SceneFrames s(29, RenderView::kDistance);
  s.cases.push_back(
      {"the middle slice, framing camera", {}, Camera::framing(s.domain, s.aspect), s.options});
  // Slab borders lie on multiples of 8 (and at the domain's faces): cuts on either side of one,
  // the bottom and the top slice.
  for (const int z : {-13, 7, 8, 15, 16, 31, 47}) {
    Case c{"slice z=" + std::to_string(z), {}, Camera::framing(s.domain, s.aspect, 40), s.options};
    c.options.slice_z = z;
    s.cases.push_back(c);
  }
  Case top{"orthographic from above, Euclidean skip clamped at 12",
           {},
           Camera::top(s.domain, s.aspect),
           s.options};
  top.scene.skip_metric = Metric::kEuclidean;
  top.scene.skip_max_distance_vox = 12;
  top.options.slice_z = 20;
  s.cases.push_back(top);
  Case below{"from below the ground (rays rise: no ray enters through the cut)",
             {},
             Camera::parse("eye=17,25,-40:target=17,25,10:up=0,1,0", s.domain, s.aspect),
             s.options};
  s.cases.push_back(below);
  Case plain{
      "no lighting field, chunk skipping", {}, Camera::framing(s.domain, s.aspect), s.options};
  plain.scene.lighting_field = false;
  plain.options.ambient_occlusion = false;
  plain.options.soft_shadows = false;
  plain.options.skip = SkipMode::kChunks;
  plain.options.slice_z = 3;
  s.cases.push_back(plain);
  s.check_all();
}

// Every rank walks its stretch of every primary ray at once, and the first hit along the ray is the
// pixel's. Hits on two ranks can share their t: where a ray crosses a voxel edge lying on a slab
// border, the plain DDA crosses x (entering a voxel above the border) and z (entering the one
// below) at one t. Here the middle row of an image of odd height looks along (1, 0, -1) from a
// whole-number eye, so each of its rays crosses x and z together, and meets the face x = 40 of a
// wall at z = 32, the border between slabs at 2 and 4 ranks: the voxel above the border, entered
// through its x face, is the hit (the one below, entered at the same t through its z face, would
// shade another way).
TEST(MpiRender, RaysThroughVoxelEdgesOnASlabBorderKeepTheirFirstHit) {
  const int edge = 8;
  const Box3i domain{{0, 0, 0}, {64, 40, 64}};
  World w(edge, domain);
  w.voxels.fill({{0, 0, 0}, {64, 40, 2}}, 1);
  w.voxels.fill({{40, 0, 0}, {44, 40, 64}}, 3);
  RenderOptions o;
  o.width = 96;
  o.height = 63;  // odd: the middle row's rays have no vertical component in the image
  const Camera cam = Camera::parse("eye=10,20,62:target=40,20,32:fov=70", domain, 96.0 / 63);
  check({"rays through voxel edges on a slab border", {}, cam, o}, w, domain, edge);
  // And level: the middle row's rays keep z = 33.5 exactly, in one slab, which the others skip.
  const Camera level = Camera::parse("eye=10,20,33.5:target=60,20,33.5:fov=60", domain, 96.0 / 63);
  check({"level rays, in one slab", {}, level, o}, w, domain, edge);
}

// The time a ray enters the whole box comes from the box's planes (traverse.h's start_in_box), its
// later events from the DDA's formula (dda.h), which can be an ulp earlier. The centre pixel of
// this 95 x 63 image looks along (40, 0, -2) exactly and enters the box through the face x = 0 at
// z = 32, on the slab border at 2 and 4 ranks, with its z crossing an ulp before its entry: the
// wall's voxel above the border, entered first, is the hit, not the one below.
TEST(MpiRender, ARayEnteringTheBoxOnASlabBorderKeepsItsFirstHit) {
  const int edge = 8;
  const Box3i domain{{0, 0, 0}, {64, 64, 64}};
  World w(edge, domain);
  w.voxels.fill({{0, 0, 0}, {4, 64, 64}}, 2);
  RenderOptions o;
  o.width = 95;
  o.height = 63;
  const Camera cam = Camera::parse("eye=-40,20,34:target=0,20,32:fov=50", domain, 95.0 / 63);
  check({"a ray entering the box on a slab border", {}, cam, o}, w, domain, edge);
}

TEST(MpiRender, BadOptionsFailOnEveryRankAlike) {
  const int edge = 8;
  const Box3i domain{{0, 0, 0}, {24, 24, 32}};
  const World w = scene_world(3, domain, edge);
  const mpi::SlabPartition p = mpi::partition_slabs(domain, ranks(), ranks() <= 4 ? edge : 1);
  RenderOptions o;
  o.width = 32;
  o.height = 24;
  o.view = RenderView::kError;
  const Camera cam = Camera::framing(domain, 32.0 / 24);
  try {
    (void)mpi::render(comm(), p, w, {}, cam, o);
    ADD_FAILURE() << "the error view was drawn";
  } catch (const mpi::RankError& e) {
    EXPECT_NE(std::string(e.what()).find("not drawn part by part"), std::string::npos) << e.what();
  }
  o.view = RenderView::kDistance;
  o.slice_z = 32;
  try {
    (void)mpi::render(comm(), p, w, {}, cam, o);
    ADD_FAILURE() << "a slice outside the box was drawn";
  } catch (const mpi::RankError& e) {
    EXPECT_NE(std::string(e.what()).find("slice z=32 lies outside"), std::string::npos) << e.what();
  }
  o.slice_z.reset();
  o.view = RenderView::kShaded;
  RenderSceneOptions bad;
  bad.skip_max_distance_vox = 300;
  try {
    (void)mpi::render(comm(), p, w, bad, cam, o);
    ADD_FAILURE() << "a skip clamp of 300 was taken";
  } catch (const mpi::RankError& e) {
    EXPECT_NE(std::string(e.what()).find("skip_max_distance_vox"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace voxfield
