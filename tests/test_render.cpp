// The renderer against oracles: skipping traversals agree bit for bit with the plain DDA; the
// plain DDA agrees with brute-force ray/box intersection over every solid voxel; the top camera
// sees the highest voxel of every column; automatic framing keeps the box in view and fills it;
// frames do not depend on threads or tiles; golden images of tiny scenes within a tolerance.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>

#include "executor_scene.h"
#include "image_compare.h"
#include "voxfield/edit.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"
#include "voxfield/png.h"
#include "voxfield/render.h"
#include "voxfield/render_executor.h"

using namespace voxfield;

namespace {

// Clusters of boxes centred at x < max_x, leaving whole chunks empty beyond.
World random_world(Vec3i size, int chunk_edge, std::uint32_t seed, int clusters,
                   int max_x = 1 << 30) {
  World w(chunk_edge, Box3i::from_size(size));
  std::mt19937 rng(seed);
  auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  for (int c = 0; c < clusters; ++c) {
    const Vec3i centre{uni(0, std::min(size.x, max_x) - 1), uni(0, size.y - 1), uni(0, size.z - 1)};
    const int spread = uni(1, 6);
    for (int k = 0; k < 12; ++k) {
      const Vec3i p{std::clamp(centre.x + uni(-spread, spread), 0, size.x - 1),
                    std::clamp(centre.y + uni(-spread, spread), 0, size.y - 1),
                    std::clamp(centre.z + uni(-spread, spread), 0, size.z - 1)};
      const Vec3i extent{uni(1, 3), uni(1, 3), uni(1, 3)};
      const Box3i b = Box3i{p, p + extent}.intersect(Box3i::from_size(size));
      w.voxels.fill(b, static_cast<std::uint8_t>(uni(1, 255)));
    }
  }
  return w;
}

void expect_same_hit(const RayHit& a, const RayHit& b, const std::string& what) {
  ASSERT_EQ(a.hit, b.hit) << what;
  if (!a.hit) return;
  EXPECT_EQ(a.voxel, b.voxel) << what;
  EXPECT_EQ(a.face_axis, b.face_axis) << what;
  EXPECT_EQ(a.face_sign, b.face_sign) << what;
  EXPECT_EQ(a.t, b.t) << what;  // bit for bit: the skipping DDA reproduces the plain one exactly
  EXPECT_EQ(a.material, b.material) << what;
}

std::vector<Ray> test_rays(const Box3i& box, std::uint32_t seed, int random_count) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(-12, 12), unit(-1, 1);
  std::vector<Ray> rays;
  const Vec3i s = box.size();
  for (int i = 0; i < random_count; ++i) {
    const Vec3d o{box.begin.x + (s.x / 2.0) + pos(rng) * s.x / 16,
                  box.begin.y + (s.y / 2.0) + pos(rng) * s.y / 16,
                  box.begin.z + (s.z / 2.0) + pos(rng) * s.z / 16};
    Vec3d d{unit(rng), unit(rng), unit(rng)};
    if (d.length() < 1e-3) d = {1, 0.5, 0.25};
    rays.push_back({o, d});
  }
  // Degenerate directions whose events tie exactly (edges and corners crossed at once), from
  // integer and half-integer origins.
  const Vec3d dirs[] = {{1, 0, 0},  {0, -1, 0}, {0, 0, 1},  {1, 1, 1}, {-1, 1, -1},
                        {1, -1, 0}, {2, 1, 0},  {0, 3, -1}, {1, 1, 2}, {-4, 2, 1}};
  std::uniform_int_distribution<int> coord(-3, 40);
  for (const Vec3d& d : dirs)
    for (int k = 0; k < 60; ++k) {
      const double half = (k % 2) * 0.5;
      rays.push_back({{coord(rng) + half, coord(rng) + half, static_cast<double>(coord(rng))}, d});
      rays.push_back(
          {{box.begin.x - 5.0 + k % 7, box.begin.y + k % 13 + half, box.begin.z + k % 11 + 0.0},
           d});
    }
  return rays;
}

}  // namespace

TEST(Render, SkippingNeverChangesAHit) {
  for (int chunk_edge : {8, 16}) {
    for (Metric metric : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
      const Vec3i size{61, 38, 29};  // not multiples of the chunk edge; empty chunks at x >= 32
      const World w = random_world(size, chunk_edge, 17u + chunk_edge, 30, 24);
      RenderSceneOptions so;
      so.skip_metric = metric;
      so.lighting_field = false;
      const RenderScene scene(w, so);
      TraversalCounters plain, chunks, skipping;
      int hits = 0;
      for (const Ray& r : test_rays(scene.box(), 5u + chunk_edge, 3000)) {
        const RayHit a = trace_ray(scene, r, SkipMode::kNone, &plain);
        const RayHit b = trace_ray(scene, r, SkipMode::kChunks, &chunks);
        const RayHit c = trace_ray(scene, r, SkipMode::kDistance, &skipping);
        const std::string what =
            std::string(metric_name(metric)) + " edge " + std::to_string(chunk_edge);
        expect_same_hit(a, b, what + " chunks");
        expect_same_hit(a, c, what + " distance");
        hits += a.hit;
      }
      EXPECT_GT(hits, 500);
      // And the skips are real: far fewer voxels read than the plain DDA's.
      EXPECT_LT(skipping.voxel_reads * 2, plain.voxel_reads) << metric_name(metric);
      EXPECT_GT(skipping.distance_skips, 0);
      EXPECT_GT(chunks.chunk_skips, 0);
    }
  }
}

// A pick from the world itself (no scene, no field: what the demo does when its fields live on a
// device) hits what a scene's rays hit, over the world's bounds and over a box inside them.
TEST(Render, PicksFromTheWorldItselfHitWhatTheScenesRaysHit) {
  const World w = random_world({61, 38, 29}, 8, 31, 30, 24);
  RenderSceneOptions so;
  so.lighting_field = false;
  const Box3i inner{{5, 3, 2}, {50, 30, 20}};
  for (const std::optional<Box3i>& box : {std::optional<Box3i>(), std::optional<Box3i>(inner)}) {
    const RenderScene scene(w, so, box);
    int hits = 0;
    for (const Ray& r : test_rays(scene.box(), 41, 3000)) {
      const RayHit want = trace_ray(scene, r, SkipMode::kNone);
      expect_same_hit(trace_ray(w, r, box), want, box ? "inner box" : "world bounds");
      hits += want.hit;
    }
    EXPECT_GT(hits, 500);
  }
  EXPECT_THROW((void)trace_ray(w, Ray{{0, 0, 0}, {0, 0, 0}}), InvalidArgument);
  EXPECT_THROW((void)trace_ray(w, Ray{{0, 0, 0}, {1, 0, 0}}, Box3i{}), InvalidArgument);
}

// Batches walk their rays in turns (src/render/ray_group.h): every hit and every counter must be
// what the rays traced one by one give, for every metric and skip mode, and for a batch whose
// last group is partial.
TEST(Render, BatchTracingEqualsSingleRays) {
  const World w = random_world({50, 40, 30}, 8, 23, 20, 30);
  for (Metric metric : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
    RenderSceneOptions so;
    so.skip_metric = metric;
    so.lighting_field = false;
    const RenderScene scene(w, so);
    std::vector<Ray> rays = test_rays(scene.box(), 8, 2000);
    rays.resize(rays.size() - 3);  // not a whole number of groups
    for (SkipMode mode : {SkipMode::kNone, SkipMode::kChunks, SkipMode::kDistance}) {
      const std::string what = std::string(metric_name(metric)) + " " + skip_mode_name(mode);
      RayHit stale;  // what a batch must overwrite for every ray, misses included
      stale.hit = true;
      stale.voxel = {-7, -7, -7};
      std::vector<RayHit> hits(rays.size(), stale);
      TraversalCounters batch, single;
      trace_rays(scene, rays, hits, mode, &batch);
      int hit_count = 0;
      for (std::size_t i = 0; i < rays.size(); ++i) {
        expect_same_hit(hits[i], trace_ray(scene, rays[i], mode, &single),
                        what + " ray " + std::to_string(i));
        hit_count += hits[i].hit;
      }
      EXPECT_GT(hit_count, 300) << what;
      EXPECT_LT(hit_count, static_cast<int>(rays.size()) - 300) << what;  // misses too
      EXPECT_EQ(batch.rays, static_cast<std::int64_t>(rays.size())) << what;
      EXPECT_EQ(batch.steps, single.steps) << what;
      EXPECT_EQ(batch.voxel_reads, single.voxel_reads) << what;
      EXPECT_EQ(batch.chunk_skips, single.chunk_skips) << what;
      EXPECT_EQ(batch.distance_skips, single.distance_skips) << what;
    }
  }
  const RenderScene scene(w);
  const std::vector<Ray> rays = test_rays(scene.box(), 8, 10);
  std::vector<RayHit> short_hits(3);
  EXPECT_THROW(trace_rays(scene, rays, short_hits), InvalidArgument);
}

TEST(Render, DdaMatchesBruteForceRayBoxIntersection) {
  const Vec3i size{21, 17, 13};
  const World w = random_world(size, 8, 99, 14);
  RenderSceneOptions so;
  so.lighting_field = false;
  const RenderScene scene(w, so);
  std::vector<Vec3i> solids;
  for (int z = 0; z < size.z; ++z)
    for (int y = 0; y < size.y; ++y)
      for (int x = 0; x < size.x; ++x)
        if (w.voxels.get({x, y, z})) solids.push_back({x, y, z});
  ASSERT_GT(solids.size(), 50u);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> pos(-8, 30), unit(-1, 1);
  int hits = 0;
  for (int i = 0; i < 2000; ++i) {
    const Ray r{{pos(rng), pos(rng), pos(rng)}, {unit(rng), unit(rng), unit(rng)}};
    // The oracle: slab test against every solid voxel, first entry at t >= 0.
    double best = std::numeric_limits<double>::infinity();
    Vec3i best_voxel{};
    int best_axis = -1;
    for (const Vec3i& v : solids) {
      double t0 = -1e300, t1 = 1e300;
      int axis = -1;
      for (int a = 0; a < 3; ++a) {
        double ta = (v[a] - r.origin[a]) / r.direction[a],
               tb = (v[a] + 1 - r.origin[a]) / r.direction[a];
        if (ta > tb) std::swap(ta, tb);
        if (ta > t0) {
          t0 = ta;
          axis = a;
        }
        t1 = std::min(t1, tb);
      }
      if (t1 <= std::max(t0, 0.0)) continue;
      const double t = std::max(t0, 0.0);
      if (t < best) {
        best = t;
        best_voxel = v;
        best_axis = t0 > 0 ? axis : -1;
      }
    }
    const RayHit h = trace_ray(scene, r, SkipMode::kDistance);
    ASSERT_EQ(h.hit, std::isfinite(best)) << "ray " << i;
    if (!h.hit) continue;
    ++hits;
    EXPECT_EQ(h.voxel, best_voxel) << "ray " << i;
    EXPECT_EQ(h.face_axis, best_axis) << "ray " << i;
    EXPECT_NEAR(h.t, best, 1e-9 * (1 + best)) << "ray " << i;
    if (best_axis >= 0) {
      EXPECT_EQ(h.face_sign, r.direction[best_axis] > 0 ? -1 : 1);
    }
    EXPECT_EQ(h.material, w.voxels.get(best_voxel));
  }
  EXPECT_GT(hits, 200);
}

TEST(Render, TopCameraSeesTheHighestVoxelOfEveryColumn) {
  const Vec3i size{40, 24, 20};
  World w(8, Box3i::from_size(size));
  std::mt19937 rng(11);
  std::vector<int> top(static_cast<std::size_t>(size.x * size.y), -1);
  for (int y = 0; y < size.y; ++y)
    for (int x = 0; x < size.x; ++x) {
      const int h = std::uniform_int_distribution<int>(-1, size.z - 1)(rng);
      if (h >= 0)
        w.voxels.fill(Box3i{{x, y, 0}, {x + 1, y + 1, h + 1}}, static_cast<std::uint8_t>(1 + h));
      top[static_cast<std::size_t>(y * size.x + x)] = h;
    }
  RenderSceneOptions so;
  so.lighting_field = false;
  const RenderScene scene(w, so);
  // Image the size of the box: pixel (i, j) is column (i, size.y - 1 - j), exactly.
  const Camera cam = Camera::parse("top", scene.box(), static_cast<double>(size.x) / size.y);
  for (int j = 0; j < size.y; ++j)
    for (int i = 0; i < size.x; ++i) {
      const Ray r = cam.ray(i, j, size.x, size.y);
      EXPECT_DOUBLE_EQ(r.origin.x, i + 0.5);
      EXPECT_DOUBLE_EQ(r.origin.y, size.y - 1 - j + 0.5);
      const RayHit h = trace_ray(scene, r);
      const int expect = top[static_cast<std::size_t>((size.y - 1 - j) * size.x + i)];
      ASSERT_EQ(h.hit, expect >= 0);
      if (!h.hit) continue;
      EXPECT_EQ(h.voxel, (Vec3i{i, size.y - 1 - j, expect}));
      EXPECT_EQ(h.face_axis, 2);
      EXPECT_EQ(h.face_sign, 1);
    }
  // A wider image: y fills the height exactly, x is centred.
  const Camera wide = Camera::top(scene.box(), 2.0 * size.x / size.y);
  EXPECT_DOUBLE_EQ(wide.ray(0, 0, 2 * size.x, size.y).origin.y, size.y - 0.5);
  EXPECT_DOUBLE_EQ(wide.ray(size.x / 2, 0, 2 * size.x, size.y).origin.x, 0.5);
  // A taller one: x fills the width exactly.
  const Camera tall = Camera::top(scene.box(), 0.5);
  EXPECT_DOUBLE_EQ(tall.ray(0, 0, 40, 80).origin.x, 0.5);
  EXPECT_DOUBLE_EQ(tall.ray(39, 0, 40, 80).origin.x, 39.5);
}

TEST(Render, AutomaticFramingKeepsTheBoxInViewAndFillsIt) {
  for (const Box3i& box : {Box3i::from_size({64, 64, 64}), Box3i{{-10, 5, 0}, {300, 40, 12}},
                           Box3i{{0, 0, 0}, {8, 8, 200}}}) {
    for (double aspect : {16.0 / 9, 1.0, 0.5}) {
      const Camera c = Camera::framing(box, aspect);
      const auto p = c.projector(100, 100);
      double widest = 0;
      for (int k = 0; k < 8; ++k) {
        const Vec3d corner{double(k & 1 ? box.end.x : box.begin.x),
                           double(k & 2 ? box.end.y : box.begin.y),
                           double(k & 4 ? box.end.z : box.begin.z)};
        const Vec3d q = corner - p.eye;
        const double depth = dot(q, p.forward);
        ASSERT_GT(depth, 0);
        const double x = dot(q, p.right) / depth / (p.scale * aspect),
                     y = dot(q, p.up) / depth / p.scale;
        EXPECT_LE(std::abs(x), 1.0) << to_string(box) << " aspect " << aspect;
        EXPECT_LE(std::abs(y), 1.0) << to_string(box) << " aspect " << aspect;
        widest = std::max({widest, std::abs(x), std::abs(y)});
      }
      EXPECT_GT(widest, 0.9) << "framing too loose for " << to_string(box);
    }
  }
}

TEST(Render, CameraStrings) {
  const Box3i box = Box3i::from_size({10, 10, 10});
  const Camera c = Camera::parse("eye=1,2,3:target=4,5,6:fov=40", box, 1);
  EXPECT_EQ(c.projection, Camera::Projection::kPerspective);
  EXPECT_DOUBLE_EQ(c.eye.y, 2);
  EXPECT_DOUBLE_EQ(c.target.z, 6);
  EXPECT_DOUBLE_EQ(c.fov_degrees, 40);
  EXPECT_EQ(Camera::parse("eye=0,0,20:target=0,0,0:up=0,1,0:ortho=12", box, 1).projection,
            Camera::Projection::kOrthographic);
  for (const char* bad :
       {"eye=1,2:target=0,0,0", "eye=1,2,3", "eye=1,2,x:target=0,0,0", "eye=0,0,0:target=0,0,0",
        "eye=0,0,1:target=0,0,0:fov=200", "eye=0,0,1:target=0,0,0", "zoom=2", "sideways"})
    EXPECT_THROW(Camera::parse(bad, box, 1), InvalidArgument) << bad;
}

namespace {

// A tiny scene with the features the shading has to get right: a floor, pillars, an overhang
// that casts a shadow, a ball, a concave corner for ambient occlusion.
World tiny_scene() {
  World w(8, Box3i::from_size({32, 28, 20}));
  w.voxels.fill(Box3i{{0, 0, 0}, {32, 28, 2}}, 200);   // floor
  w.voxels.fill(Box3i{{3, 3, 2}, {6, 6, 14}}, 30);     // pillar
  w.voxels.fill(Box3i{{3, 3, 14}, {20, 8, 16}}, 30);   // overhang
  w.voxels.fill(Box3i{{24, 2, 2}, {30, 26, 8}}, 120);  // wall: concave corner with the floor
  for (int z = 2; z < 20; ++z)
    for (int y = 0; y < 28; ++y)
      for (int x = 0; x < 32; ++x) {
        const double dx = x + 0.5 - 14, dy = y + 0.5 - 17, dz = z + 0.5 - 7;
        if (dx * dx + dy * dy + dz * dz <= 25) w.voxels.set({x, y, z}, 5);  // ball
      }
  return w;
}

std::filesystem::path golden_dir() {
  return VOXFIELD_GOLDEN_DIR;
}

// Within tolerance: every channel within 8 levels on 99.5 % of pixels, mean difference < 0.5.
void expect_matches_golden(const Image& got, const std::string& name) {
  const std::filesystem::path path = golden_dir() / (name + ".png");
  if (std::getenv("VOXFIELD_UPDATE_GOLDEN")) {
    write_png(got, path);
    GTEST_SKIP() << "rewrote " << path;
  }
  const Image want = read_png(path);
  ASSERT_EQ(want.width, got.width);
  ASSERT_EQ(want.height, got.height);
  const test::ImageDiff d = test::compare_images(got, want, 8);
  EXPECT_LE(d.off, d.pixels / 200)
      << name << ": " << d.off << " pixels differ by more than 8 levels";
  EXPECT_LT(d.mean, 0.5) << name;
  if (::testing::Test::HasFailure())
    write_png(got, std::filesystem::temp_directory_path() / (name + "-actual.png"));
}

}  // namespace

TEST(Render, GoldenImagesOfATinyScene) {
  const World w = tiny_scene();
  const RenderScene scene(w);
  RenderOptions o;
  o.width = 96;
  o.height = 64;
  const Camera cam = Camera::framing(scene.box(), 1.5);
  expect_matches_golden(render(scene, cam, o), "tiny-shaded");
  o.view = RenderView::kChunks;
  expect_matches_golden(render(scene, cam, o), "tiny-chunks");
  o.view = RenderView::kDistance;
  o.slice_z = 3;
  expect_matches_golden(render(scene, Camera::top(scene.box(), 1.5), o), "tiny-distance-top");
  o.view = RenderView::kShaded;
  o.fog_density = 0.02;
  expect_matches_golden(render(scene, cam, o), "tiny-fog");
}

TEST(Render, FramesDoNotDependOnThreadsOrTiles) {
  const World w = tiny_scene();
  const RenderScene scene(w);
  RenderOptions o;
  o.width = 80;
  o.height = 50;
  const Camera cam = Camera::framing(scene.box(), 1.6);
  Image one;
  {
    ThreadLimit limit(1);
    o.tile_size = 16;
    one = render(scene, cam, o);
  }
  o.tile_size = 7;
  const Image many = render(scene, cam, o);
  EXPECT_EQ(one.rgb, many.rgb);
}

// Frames skipping by the distance field walk their primary rays in turns (ray_group.h); frames
// without skips walk them one by one. They must be the same picture, with the same counts.
TEST(Render, FramesDoNotDependOnHowRaysSkip) {
  const World w = random_world({70, 60, 40}, 8, 31, 40, 50);
  for (Metric metric : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
    RenderSceneOptions so;
    so.skip_metric = metric;
    const RenderScene scene(w, so);
    RenderOptions o;
    o.width = 83;  // rows of whole and partial groups
    o.height = 47;
    o.tile_size = 13;
    const Camera cam = Camera::framing(scene.box(), 1.6);
    for (RenderView view : {RenderView::kShaded, RenderView::kChunks}) {
      o.view = view;
      RenderStats plain_stats, skip_stats;
      o.skip = SkipMode::kNone;
      const Image plain = render(scene, cam, o, &plain_stats);
      o.skip = SkipMode::kDistance;
      const Image skipping = render(scene, cam, o, &skip_stats);
      EXPECT_EQ(plain.rgb, skipping.rgb) << metric_name(metric) << " " << render_view_name(view);
      EXPECT_EQ(plain_stats.primary.rays, skip_stats.primary.rays);
      EXPECT_EQ(plain_stats.shadow.rays, skip_stats.shadow.rays);
      EXPECT_LT(skip_stats.primary.voxel_reads * 2, plain_stats.primary.voxel_reads);
    }
  }
}

TEST(Render, ShadowsDarkenWhatTheOverhangCovers) {
  // Sun straight above; small orthographic views of the floor from an eye below the overhang:
  // the floor under the overhang must be much darker than open floor of the same material.
  const World w = tiny_scene();
  const RenderScene scene(w);
  RenderOptions o;
  o.width = o.height = 4;
  o.sun_direction = {0, 0, 1};
  o.ambient_occlusion = false;
  auto floor_brightness = [&](double x, double y) {
    const std::string spec = "eye=" + std::to_string(x) + "," + std::to_string(y) +
                             ",10:target=" + std::to_string(x) + "," + std::to_string(y) +
                             ",0:up=0,1,0:ortho=2";
    const Image img = render(scene, Camera::parse(spec, scene.box(), 1), o);
    const std::uint8_t* p = img.pixel(2, 2);
    return p[0] + p[1] + p[2];
  };
  const int under = floor_brightness(12.5, 5.5), open = floor_brightness(20.5, 22.5);
  // Sky light still reaches the shadowed floor, and exposure compresses the ratio: a quarter
  // darker is a clear shadow, unshadowed floors differ by nothing.
  EXPECT_LT(under * 4, open * 3) << "the floor under the overhang is not in shadow";
  o.soft_shadows = false;
  EXPECT_EQ(floor_brightness(12.5, 5.5), floor_brightness(20.5, 22.5))
      << "without shadows both are lit alike";
}

TEST(Render, ErrorViewOfTheExactFieldFindsNoError) {
  const World w = random_world({40, 40, 24}, 8, 5, 8);
  const RenderScene scene(w);
  RenderOptions o;
  o.width = 64;
  o.height = 40;
  o.view = RenderView::kError;
  o.error_algorithm = Algorithm::kExact;
  RenderStats st;
  render(scene, Camera::framing(scene.box(), 1.6), o, &st);
  EXPECT_EQ(st.rays_through_geometry, 0);
  EXPECT_EQ(st.max_error, 0);
  // The dissertation's value-propagating JFA is wrong somewhere on this world.
  o.error_algorithm = Algorithm::kJfaSeed;
  render(scene, Camera::framing(scene.box(), 1.6), o, &st);
  EXPECT_GT(st.max_error, 0);
}

TEST(Render, BadRequestsAreRefused) {
  const World w = tiny_scene();
  RenderSceneOptions no_light;
  no_light.lighting_field = false;
  const RenderScene scene(w, no_light);
  const Camera cam = Camera::framing(scene.box(), 1);
  RenderOptions o;
  o.width = 0;
  EXPECT_THROW(render(scene, cam, o), InvalidArgument);
  o.width = 16;
  o.height = 16;
  EXPECT_THROW(render(scene, cam, o), InvalidArgument);  // shadows without a lighting field
  o.soft_shadows = o.ambient_occlusion = false;
  EXPECT_NO_THROW(render(scene, cam, o));
  o.view = RenderView::kDistance;
  o.slice_z = 99;
  EXPECT_THROW(render(scene, cam, o), InvalidArgument);
  EXPECT_THROW(trace_ray(scene, Ray{{0, 0, 0}, {0, 0, 0}}), InvalidArgument);
  EXPECT_THROW(RenderScene(World(8)), InvalidArgument);  // nothing to render
  EXPECT_THROW(parse_render_view("xray"), InvalidArgument);
  EXPECT_THROW(parse_skip_mode("lots"), InvalidArgument);
}

TEST(Png, RoundTripAndMalformedFiles) {
  const auto dir = std::filesystem::temp_directory_path() / "voxfield-png-test";
  std::filesystem::create_directories(dir);
  Image img(7, 5);
  for (std::size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = static_cast<std::uint8_t>(i * 37);
  write_png(img, dir / "a.png");
  const Image back = read_png(dir / "a.png");
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgb, img.rgb);
  { std::ofstream(dir / "bad.png") << "not a png at all"; }
  EXPECT_THROW(read_png(dir / "bad.png"), FormatError);
  // A truncated file: the header survives, the pixels do not.
  const auto size = std::filesystem::file_size(dir / "a.png");
  std::filesystem::copy_file(dir / "a.png", dir / "cut.png",
                             std::filesystem::copy_options::overwrite_existing);
  std::filesystem::resize_file(dir / "cut.png", size / 2);
  EXPECT_THROW(read_png(dir / "cut.png"), FormatError);
  EXPECT_THROW(read_png(dir / "missing.png"), IoError);
  EXPECT_THROW(write_png(img, dir / "no-such-dir" / "x.png"), IoError);
  EXPECT_THROW(Image(0, 3), InvalidArgument);
  std::filesystem::remove_all(dir);
}

TEST(Render, ScenesFollowEditsExactly) {
  // A seeded stream of places, carves and paints across chunk borders and world bounds: after
  // every few edits the incrementally updated scene renders and traces exactly like a scene built
  // from scratch (bit for bit), and only chunks near the edits change.
  World w = random_world({72, 56, 40}, 8, 77, 25);
  for (Metric m : {Metric::kManhattan, Metric::kEuclidean}) {
    RenderSceneOptions so = DynamicRenderScene::default_options();
    so.skip_metric = m;
    so.skip_max_distance_vox = m == Metric::kEuclidean ? 6 : 12;
    so.lighting_max_distance_vox = 5;
    DynamicRenderScene live(w, so);
    std::mt19937 rng(5 + static_cast<unsigned>(m));
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
    RenderOptions o;
    o.width = 72;
    o.height = 48;
    const Camera cam = Camera::framing(live.scene().box(), 1.5);
    const std::vector<Ray> rays = test_rays(live.scene().box(), 3, 300);
    for (int e = 1; e <= 60; ++e) {
      const Vec3d c{static_cast<double>(uni(-3, 74)), static_cast<double>(uni(-3, 58)),
                    static_cast<double>(uni(-3, 42))};
      const int op = uni(0, 2);
      Edit edit{op == 0   ? EditOp::kPlace
                : op == 1 ? EditOp::kCarve
                          : EditOp::kPaint,
                SphereBrush{c, uni(1, 7) * 1.0}, static_cast<std::uint8_t>(uni(1, 255))};
      if (e % 7 == 0)
        edit.brush =
            BoxBrush{{uni(0, 60), uni(0, 40), uni(0, 30)}, {uni(60, 80), uni(40, 60), uni(30, 45)}};
      apply_edit(w, edit, &dirty);
      const DynamicRenderScene::UpdateStats st = live.update(dirty);
      // Only chunks within the fields' reach of a changed voxel can change: the changed box grown
      // by the larger clamp (and one voxel of rounding), counted in chunks of edge 8.
      const int reach = static_cast<int>(std::ceil(
                            std::max(so.skip_max_distance_vox, so.lighting_max_distance_vox))) +
                        1;
      const Box3i grown = dirty.bounds().empty() ? Box3i{}
                                                 : Box3i{dirty.bounds().begin - Vec3i::splat(reach),
                                                         dirty.bounds().end + Vec3i::splat(reach)}
                                                       .intersect(live.scene().box());
      std::size_t reachable = 0;
      if (!grown.empty()) {
        const Vec3i lo{grown.begin.x / 8, grown.begin.y / 8, grown.begin.z / 8};
        const Vec3i hi{(grown.end.x - 1) / 8, (grown.end.y - 1) / 8, (grown.end.z - 1) / 8};
        reachable =
            static_cast<std::size_t>(hi.x - lo.x + 1) * (hi.y - lo.y + 1) * (hi.z - lo.z + 1);
      }
      dirty.clear();
      EXPECT_LE(st.chunks_changed, reachable) << "edit " << e;
      if (e % 6 != 0) continue;
      const std::string what = std::string(metric_name(m)) + " after edit " + std::to_string(e);
      const RenderScene fresh(w, live.skip_field(), live.light_field());
      EXPECT_EQ(render(live.scene(), cam, o).rgb, render(fresh, cam, o).rgb) << what;
      o.view = RenderView::kChunks;
      EXPECT_EQ(render(live.scene(), cam, o).rgb, render(fresh, cam, o).rgb) << what;
      o.view = RenderView::kShaded;
      std::vector<RayHit> a(rays.size()), b(rays.size());
      trace_rays(live.scene(), rays, a);
      trace_rays(fresh, rays, b);
      for (std::size_t i = 0; i < rays.size(); ++i)
        expect_same_hit(a[i], b[i], what + " ray " + std::to_string(i));
      // And the fields behind it are those of full rebuilds.
      const DistanceField skip = compute_distance_field(w, live.skip_field().options);
      const Box3i box = live.scene().box();
      std::vector<std::uint8_t> want(static_cast<std::size_t>(box.volume())), got(want.size());
      std::get<Grid<std::uint8_t>>(skip.values).copy_to_dense(box, want.data());
      std::get<Grid<std::uint8_t>>(live.skip_field().values).copy_to_dense(box, got.data());
      EXPECT_EQ(want, got) << what;
    }
  }
}

TEST(Render, SceneUpdatesTouchOnlyTheChunksAnEditReaches) {
  World w(16, Box3i::from_size({128, 128, 64}));
  w.voxels.fill(Box3i{{0, 0, 0}, {128, 128, 8}}, 3);
  RenderSceneOptions so = DynamicRenderScene::default_options();
  so.skip_max_distance_vox = 8;
  so.lighting_max_distance_vox = 8;
  DynamicRenderScene live(w, so);
  DirtyRegions dirty(16, DirtyRegions::Track::kAnyChange);
  apply_edit(w, {EditOp::kPlace, SphereBrush{{64, 64, 12}, 3}, 9}, &dirty);
  const DynamicRenderScene::UpdateStats st = live.update(dirty);
  // Voxels within 8 of x, y in [61, 67] and z in [9, 15]: chunks 3..4 along x and y, 0..1 along z.
  EXPECT_GT(st.chunks_changed, 0u);
  EXPECT_LE(st.chunks_changed, 2u * 2u * 2u);
  dirty.clear();
  // Painting a voxel the same colour changes nothing.
  apply_edit(w, {EditOp::kPaint, SphereBrush{{64, 64, 12}, 0}, 9}, &dirty);
  EXPECT_EQ(live.update(dirty).chunks_changed, 0u);
  EXPECT_THROW(DynamicRenderScene(World(8)), InvalidArgument);  // unbounded
  RenderSceneOptions bad = so;
  bad.skip_max_distance_vox = 300;
  EXPECT_THROW(DynamicRenderScene(w, bad), InvalidArgument);
}

// The render module's one API on the CPU executor (every build has it): the CPU renderer's frames
// bit for bit, and a SceneView following an edit as a scene built afresh does. The Vulkan half is
// checked in test_gpu_render.cpp.
TEST(Render, TheCpuExecutorDrawsTheCpuRenderersFrames) {
  test::ExecutorScene s(random_world({40, 32, 24}, 8, 5, 12));
  const Executor cpu = Executor::choose(Backend::kCpu);
  ASSERT_FALSE(cpu.on_gpu());
  std::vector<gpu::PassTiming> timings{{"stale", 1}};
  EXPECT_EQ(render(cpu, s.scene(), s.camera(), s.options(), nullptr, nullptr, &timings).rgb,
            render(s.scene(), s.camera(), s.options()).rgb);
  EXPECT_TRUE(timings.empty());  // no device, no passes
  SceneView view(cpu);
  (void)view.render(s.scene(), s.camera(), s.options());
  const RenderScene fresh = s.edit();
  EXPECT_EQ(view.render(s.scene(), s.camera(), s.options()).rgb,
            render(fresh, s.camera(), s.options()).rgb);
}
