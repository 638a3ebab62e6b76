// Brushes and edits against per-voxel definitions, and incremental distance updates against full
// rebuilds (bit-identical, after every edit of long random streams).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <tuple>

#include "backends.h"
#include "distance/incremental/update_regions.h"  // internal: the affected-box search, tested directly
#include "voxfield/dynamic_field.h"
#include "voxfield/edit.h"
#include "voxfield/edit_stream.h"
#include "world_voxels.h"

using namespace voxfield;
using namespace voxfield::testing_backends;

namespace {

// The definition of each operation, voxel by voxel, as the oracle.
void apply_by_definition(World& w, const Edit& e) {
  Box3i box = brush_bounds(e.brush);
  if (w.voxels.bounds()) box = box.intersect(*w.voxels.bounds());
  const StampBrush* stamp = std::get_if<StampBrush>(&e.brush);
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x) {
        const Vec3i p{x, y, z};
        if (!brush_contains(e.brush, p)) continue;
        const std::uint8_t m = stamp ? stamp->model->voxels.get(p - stamp->offset) : e.material;
        const std::uint8_t old = w.voxels.get(p);
        if (e.op == EditOp::kPlace) w.voxels.set(p, m);
        if (e.op == EditOp::kCarve) w.voxels.set(p, 0);
        if (e.op == EditOp::kPaint && old != 0) w.voxels.set(p, m);
      }
}

Edit random_edit(std::mt19937& rng, const Box3i& area, const std::shared_ptr<const World>& model) {
  auto uni = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  auto coord = [&](int axis) { return uni(area.begin[axis] - 4, area.end[axis] + 4); };
  Edit e;
  e.op = static_cast<EditOp>(rng() % 3);
  e.material = static_cast<std::uint8_t>(1 + rng() % 5);
  switch (rng() % 5) {
    case 0:
      e.brush = SphereBrush{{coord(0), coord(1), coord(2)}, uni(0, 7)};
      break;
    case 1: {
      const Vec3i a{static_cast<int>(coord(0)), static_cast<int>(coord(1)),
                    static_cast<int>(coord(2))};
      e.brush = BoxBrush{a, a + Vec3i{static_cast<int>(rng() % 9), static_cast<int>(rng() % 9),
                                      static_cast<int>(rng() % 9)}};
      break;
    }
    case 2:
      e.brush = RotatedBoxBrush{{coord(0), coord(1), coord(2)},
                                {uni(0, 5), uni(0, 3), uni(0, 4)},
                                {uni(0, 90), uni(0, 90), uni(0, 90)}};
      break;
    case 3:
      e.brush =
          CapsuleBrush{{coord(0), coord(1), coord(2)}, {coord(0), coord(1), coord(2)}, uni(0, 3)};
      break;
    default:
      e.brush = StampBrush{
          model,
          {static_cast<int>(coord(0)), static_cast<int>(coord(1)), static_cast<int>(coord(2))}};
  }
  return e;
}

std::shared_ptr<const World> small_model() {
  auto m = std::make_shared<World>(8);
  for (int i = 0; i < 5; ++i)
    m->voxels.set({i, i % 2, 2 * (i % 3)}, static_cast<std::uint8_t>(10 + i));
  return m;
}

}  // namespace

TEST(Edit, EveryBrushAndOperationMatchesItsDefinition) {
  std::mt19937 rng(21);
  const Box3i bounds{{-7, 3, -20}, {40, 35, 13}};  // odd, negative, not chunk aligned
  World a(16, bounds), b(16, bounds);
  const auto model = small_model();
  DirtyRegions any(16, DirtyRegions::Track::kAnyChange),
      occupancy(16, DirtyRegions::Track::kOccupancy);
  for (int i = 0; i < 400; ++i) {
    const Edit e = random_edit(rng, bounds, model);
    const std::vector<std::uint8_t> before = test::dense_voxels(a, bounds);
    // Alternate the two kinds of tracking; each must cover the changes it is meant to.
    DirtyRegions& dirty = i % 2 ? occupancy : any;
    const EditResult r = apply_edit(a, e, &dirty);
    apply_by_definition(b, e);
    const std::vector<std::uint8_t> after = test::dense_voxels(a, bounds);
    ASSERT_EQ(after, test::dense_voxels(b, bounds)) << "edit " << i;
    // The reported count and box are exactly the changed voxels; dirty regions cover them.
    std::int64_t changed = 0;
    std::size_t k = 0;
    for (int z = bounds.begin.z; z < bounds.end.z; ++z)
      for (int y = bounds.begin.y; y < bounds.end.y; ++y)
        for (int x = bounds.begin.x; x < bounds.end.x; ++x, ++k) {
          if (before[k] == after[k]) continue;
          ++changed;
          ASSERT_TRUE(r.changed_box.contains(Vec3i{x, y, z}));
          if (dirty.track() == DirtyRegions::Track::kOccupancy &&
              (before[k] != 0) == (after[k] != 0))
            continue;
          bool covered = false;
          for (const Box3i& d : dirty.boxes()) covered |= d.contains(Vec3i{x, y, z});
          ASSERT_TRUE(covered);
        }
    ASSERT_EQ(changed, r.voxels_changed);
    dirty.clear();
  }
  // Chunks emptied by carving collapse away again.
  World c(16, bounds);
  apply_edit(c, {EditOp::kPlace, SphereBrush{{10, 10, 0}, 6}, 3});
  EXPECT_GT(c.voxels.chunk_count(), 0u);
  apply_edit(c, {EditOp::kCarve, BoxBrush{bounds.begin, bounds.end - Vec3i::splat(1)}, 1});
  EXPECT_EQ(c.voxels.chunk_count(), 0u);
}

// Spheres are applied a row run at a time (their ends settled with the test): the runs must hold
// exactly the voxels brush_contains accepts, including where voxels lie on the sphere itself
// (integer and half-integer centres with integer radii, where rounding decides), for tiny radii and
// for centres outside the world.
TEST(Edit, SphereRunsMatchTheVoxelTest) {
  const Box3i bounds{{-13, -9, -11}, {27, 29, 25}};
  World w(8, bounds);
  std::mt19937 rng(77);
  auto uni = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  for (int i = 0; i < 1500; ++i) {
    Vec3d c{uni(-20, 35), uni(-15, 35), uni(-18, 32)};
    double radius = uni(0, 18);
    switch (i % 4) {  // centres on voxels or half-way between them, radii whole or their squares
      case 0:
        c = {std::round(c[0]), std::round(c[1]), std::round(c[2])};
        radius = std::round(radius);
        break;
      case 1:
        c = {std::round(c[0]) + 0.5, std::round(c[1]), std::round(c[2]) + 0.5};
        radius = std::round(radius);
        break;
      case 2:
        radius = std::sqrt(std::round(radius * radius));
        break;
      default:
        break;
    }
    const SphereBrush sphere{c, radius};
    std::int64_t expected = 0;
    for (int z = bounds.begin.z; z < bounds.end.z; ++z)
      for (int y = bounds.begin.y; y < bounds.end.y; ++y)
        for (int x = bounds.begin.x; x < bounds.end.x; ++x)
          expected += brush_contains(sphere, Vec3i{x, y, z}) ? 1 : 0;
    ASSERT_EQ(apply_edit(w, {EditOp::kPlace, sphere, 1}).voxels_changed, expected)
        << "sphere " << i;
    ASSERT_EQ(w.solid_count(), expected) << "sphere " << i;
    ASSERT_EQ(apply_edit(w, {EditOp::kCarve, sphere, 1}).voxels_changed, expected)
        << "sphere " << i;
  }
}

TEST(Edit, ShapesByHand) {
  World w(8, Box3i{{-20, -20, -20}, {20, 20, 20}});
  EXPECT_EQ(apply_edit(w, {EditOp::kPlace, SphereBrush{{0, 0, 0}, 1}, 2}).voxels_changed,
            7);  // centre + 6
  EXPECT_EQ(apply_edit(w, {EditOp::kPlace, BoxBrush{{5, 5, 5}, {6, 7, 8}}, 2}).voxels_changed,
            2 * 3 * 4);
  // A box rotated 90 degrees about z swaps its x and y extents.
  World r(8, Box3i{{-20, -20, -20}, {20, 20, 20}});
  apply_edit(r, {EditOp::kPlace, RotatedBoxBrush{{0, 0, 0}, {3, 1, 0}, {0, 0, 90}}, 1});
  EXPECT_EQ(r.voxels.content_bounds(), (Box3i::from_inclusive({-1, -3, 0}, {1, 3, 0})));
  // A capsule of radius 0 is the voxels on its segment.
  World s(8, Box3i{{-20, -20, -20}, {20, 20, 20}});
  EXPECT_EQ(
      apply_edit(s, {EditOp::kPlace, CapsuleBrush{{0, 0, 0}, {5, 0, 0}, 0}, 1}).voxels_changed, 6);
  // Paint never creates matter.
  EXPECT_EQ(apply_edit(s, {EditOp::kPaint, SphereBrush{{2, 0, 0}, 3}, 9}).voxels_changed, 6);
  EXPECT_EQ(s.solid_count(), 6);
  // Clipped at the bounds; out-of-bounds edits change nothing.
  EXPECT_EQ(apply_edit(s, {EditOp::kPlace, BoxBrush{{19, 19, 19}, {30, 30, 30}}, 1}).voxels_changed,
            1);
  EXPECT_EQ(apply_edit(s, {EditOp::kPlace, SphereBrush{{100, 0, 0}, 5}, 1}).voxels_changed, 0);
  // Malformed edits are refused before anything changes.
  EXPECT_THROW(apply_edit(s, {EditOp::kPlace, SphereBrush{{0, 0, 0}, -1}, 1}), InvalidArgument);
  EXPECT_THROW(apply_edit(s, {EditOp::kPlace, BoxBrush{{1, 0, 0}, {0, 0, 0}}, 1}), InvalidArgument);
  EXPECT_THROW(apply_edit(s, {EditOp::kPlace, SphereBrush{{0, 0, 0}, 2}, 0}), InvalidArgument);
  EXPECT_THROW(apply_edit(s, {EditOp::kPlace, StampBrush{nullptr, {0, 0, 0}}, 1}), InvalidArgument);
  const double nan = std::numeric_limits<double>::quiet_NaN(),
               inf = std::numeric_limits<double>::infinity();
  EXPECT_THROW(apply_edit(s, {EditOp::kPlace, SphereBrush{{nan, 0, 0}, 2}, 1}), InvalidArgument);
  EXPECT_THROW(apply_edit(s, {EditOp::kCarve, CapsuleBrush{{0, 0, 0}, {inf, 0, 0}, 1}, 1}),
               InvalidArgument);
  EXPECT_THROW(
      apply_edit(s, {EditOp::kPlace, RotatedBoxBrush{{0, 0, 0}, {1, 1, 1}, {0, nan, 0}}, 1}),
      InvalidArgument);
  EXPECT_EQ(s.solid_count(), 7);
  // A sphere centred far outside the world covers exactly its cap inside.
  World cap(8, Box3i{{-20, -20, -20}, {20, 20, 20}});
  const SphereBrush far{{1000.5, 0.25, -3}, 990};
  std::int64_t expected = 0;
  for (int z = -20; z < 20; ++z)
    for (int y = -20; y < 20; ++y)
      for (int x = -20; x < 20; ++x) expected += brush_contains(far, Vec3i{x, y, z}) ? 1 : 0;
  EXPECT_GT(expected, 1000);
  EXPECT_EQ(apply_edit(cap, {EditOp::kPlace, far, 1}).voxels_changed, expected);
  EXPECT_EQ(cap.solid_count(), expected);
}

namespace {

struct FieldCase {
  Metric metric;
  bool is_signed;
  double clamp;
  Storage storage;
  bool sites;
  std::array<double, 3> spacing{1, 1, 1};
};

void expect_same_field(const DistanceField& a, const DistanceField& b, const Box3i& box, int step) {
  std::visit(
      [&](const auto& ga) {
        using G = std::decay_t<decltype(ga)>;
        const G& gb = std::get<G>(b.values);
        std::vector<typename G::value_type> va(static_cast<std::size_t>(box.volume())),
            vb(va.size());
        ga.copy_to_dense(box, va.data());
        gb.copy_to_dense(box, vb.data());
        ASSERT_TRUE(std::memcmp(va.data(), vb.data(), va.size() * sizeof(va[0])) == 0)
            << "values differ after edit " << step;
      },
      a.values);
  ASSERT_EQ(a.sites.has_value(), b.sites.has_value());
  if (a.sites) {
    std::vector<SiteOffset> sa(static_cast<std::size_t>(box.volume())), sb(sa.size());
    a.sites->copy_to_dense(box, sa.data());
    b.sites->copy_to_dense(box, sb.data());
    ASSERT_TRUE(sa == sb) << "sites differ after edit " << step;
  }
}

}  // namespace

// The cases come in two halves (the second parameter), so that ctest's jobs share them.
class DynamicFieldOn : public ::testing::TestWithParam<std::tuple<Backend, int>> {};
INSTANTIATE_TEST_SUITE_P(Backends, DynamicFieldOn,
                         ::testing::Combine(::testing::Values(Backend::kCpu, Backend::kVulkan),
                                            ::testing::Values(0, 1)),
                         [](const ::testing::TestParamInfo<std::tuple<Backend, int>>& info) {
                           return std::string(backend_name(std::get<0>(info.param))) + "_half" +
                                  std::to_string(std::get<1>(info.param));
                         });

TEST_P(DynamicFieldOn, IncrementalUpdatesEqualFullRebuilds) {
  const auto [b, half] = GetParam();
  VOXFIELD_SKIP_UNLESS_BACKEND(b);
  const FieldCase all_cases[] = {
      {Metric::kManhattan, false, 6, Storage::kF32, true},
      {Metric::kEuclidean, true, 5, Storage::kF32, true},
      {Metric::kChebyshev, true, 4, Storage::kU8, false},
      {Metric::kEuclidean, false, 0, Storage::kU8, true},
      {Metric::kManhattan, true, 3, Storage::kU16, true},
      {Metric::kEuclidean, false, 7.5, Storage::kU16, false},
      {Metric::kEuclidean, true, 6, Storage::kF32, false, {0.5, 1.0, 2.0}},
      // Unsigned without sites: the local pass's fast encoding.
      {Metric::kChebyshev, false, 5, Storage::kU8, false},
      {Metric::kEuclidean, false, 6, Storage::kF32, false},
      {Metric::kManhattan, false, 9, Storage::kU16, false},
      // Unclamped, and unequal spacings (Euclidean only): the affected-box search's rounding slack
      // and the bound on new values after removals depend on the metric and the spacing.
      {Metric::kEuclidean, false, 0, Storage::kF32, false, {1.0, 0.5, 2.0}},
      {Metric::kEuclidean, false, 5, Storage::kU16, false, {0.5, 1.0, 1.0}},
      {Metric::kChebyshev, false, 0, Storage::kF32, false},
      // Signed Euclidean with unit spacing and no sites: the truncated min-convolution's two
      // transforms (to solid, to air), a small clamp and one past the world's extent.
      {Metric::kEuclidean, true, 6, Storage::kU8, false},
      {Metric::kEuclidean, true, 40.5, Storage::kF32, false},
  };
  const Box3i bounds{{-9, 0, 4}, {43, 37, 33}};
  const auto model = small_model();
  const std::size_t n_cases = std::size(all_cases), first = half == 0 ? 0 : n_cases / 2,
                    end = half == 0 ? n_cases / 2 : n_cases;
  int total_edits = 0, cases_run = 0;
  // On Vulkan every update runs, and every tenth is read back and checked (each check is two
  // submissions with read-backs on a software device).
  const int check_every = b == Backend::kVulkan ? 10 : 1;
  // Under a sanitizer, 120 updates per case instead of 250 (the same edits, cases and checks; the
  // optimised build runs all 250).
  const int updates = kSanitizedBuild ? 120 : 250;
  for (std::size_t ci = first; ci < end; ++ci) {
    const FieldCase& c = all_cases[ci];
    const std::uint32_t seed = 100 + static_cast<std::uint32_t>(ci);
    if (b == Backend::kVulkan && c.spacing != std::array<double, 3>{1, 1, 1}) continue;
    if (b == Backend::kVulkan && kSanitizedBuild && ci % 4 != 0) continue;
    ++cases_run;
    SCOPED_TRACE(std::string(backend_name(b)) + " " + std::string(metric_name(c.metric)) +
                 (c.is_signed ? " signed" : "") + " clamp " + std::to_string(c.clamp) + " " +
                 storage_name(c.storage));
    std::mt19937 rng(seed);
    World w(16, bounds);
    for (int i = 0; i < 40; ++i) apply_edit(w, random_edit(rng, bounds, model));
    DistanceOptions o;
    o.metric = c.metric;
    o.signed_distance = c.is_signed;
    o.max_distance = c.clamp;
    o.storage = c.storage;
    o.nearest_sites = c.sites;
    o.spacing = c.spacing;
    IncrementalDistanceField live(executor_of(b), w, o);
    DirtyRegions dirty(
        16, seed % 2 ? DirtyRegions::Track::kOccupancy : DirtyRegions::Track::kAnyChange);
    for (int i = 0; i < updates; ++i) {
      // One to three edits between updates: placements, deletions and paints, across chunk
      // borders and reaching past the world's bounds.
      const int batch = 1 + static_cast<int>(rng() % 3);
      for (int k = 0; k < batch; ++k) apply_edit(w, random_edit(rng, bounds, model), &dirty);
      total_edits += batch;
      live.update(dirty);
      dirty.clear();
      if (i % check_every != 0 && i != updates - 1) continue;
      const DistanceField full = exact_field(b, w, live.options());
      expect_same_field(live.field(), full, bounds, i);
      if (HasFatalFailure()) return;
    }
  }
  // `updates` updates of one to three edits each (two on average), per case.
  EXPECT_GE(cases_run, 1);
  EXPECT_GT(total_edits, updates * 8 / 5 * cases_run);
  expect_no_validation_messages(b);
}

// Edits in and under solid ground: holes whose new values are bounded by the ground around them
// (the update reads only the sites that bound allows), placements and carves at the surface and
// in caves, one per update, against full rebuilds.
TEST(DynamicField, EditsInSolidGroundEqualFullRebuilds) {
  const Box3i bounds = Box3i::from_size({70, 44, 66});
  const FieldCase cases[] = {
      {Metric::kEuclidean, false, 12, Storage::kF32, false},
      {Metric::kManhattan, false, 10, Storage::kU8, false},
      {Metric::kChebyshev, false, 8, Storage::kU16, false},
      {Metric::kEuclidean, false, 0, Storage::kU8, false},
      {Metric::kEuclidean, false, 9, Storage::kU16, false, {1.0, 0.5, 1.5}},
  };
  std::uint32_t seed = 7;
  for (const FieldCase& c : cases) {
    SCOPED_TRACE(std::string(metric_name(c.metric)) + " clamp " + std::to_string(c.clamp) + " " +
                 storage_name(c.storage));
    std::mt19937 rng(seed++);
    World w(16, bounds);
    // Ground up to a wavy height with a few caves.
    for (int z = 0; z < 66; ++z)
      for (int x = 0; x < 70; ++x) {
        const int h = 28 + static_cast<int>(4 * std::sin(x * 0.21) + 3 * std::cos(z * 0.17));
        apply_edit(w, {EditOp::kPlace, BoxBrush{{x, 0, z}, {x, h, z}}, 2});
      }
    for (int i = 0; i < 6; ++i)
      apply_edit(
          w, {EditOp::kCarve,
              SphereBrush{{5.0 + rng() % 60, 4.0 + rng() % 20, 5.0 + rng() % 56}, 2.0 + rng() % 4},
              1});
    DistanceOptions o;
    o.metric = c.metric;
    o.max_distance = c.clamp;
    o.storage = c.storage;
    o.spacing = c.spacing;
    DynamicDistanceField live(w, o);
    DirtyRegions dirty(16, DirtyRegions::Track::kOccupancy);
    for (int i = 0; i < 120; ++i) {
      const double radius = static_cast<double>(rng() % 6);
      const Vec3d at{static_cast<double>(rng() % 70), static_cast<double>(rng() % 40),
                     static_cast<double>(rng() % 66)};
      Edit e{i % 3 == 2 ? EditOp::kPlace : EditOp::kCarve, SphereBrush{at, radius}, 3};
      if (i % 5 == 4)
        e.brush =
            BoxBrush{Vec3i{static_cast<int>(at.x), static_cast<int>(at.y), static_cast<int>(at.z)},
                     Vec3i{static_cast<int>(at.x) + 4, static_cast<int>(at.y) + 1,
                           static_cast<int>(at.z) + 6}};
      apply_edit(w, e, &dirty);
      live.update(dirty);
      dirty.clear();
      expect_same_field(live.field(), compute_distance_field(w, live.options()), bounds, i);
      if (HasFatalFailure()) return;
    }
  }
  // A hole carved deep in the ground: the ground around it is at 0, so the new values inside it
  // are at most 4 and, face by face, no nearest site lies more than one voxel beyond the 7^3 hole's
  // box: a 9^3 read, not the clamp's 31^3 (nor the 15^3 that the bound of 4 alone would give).
  World w(16, bounds);
  apply_edit(w, {EditOp::kPlace, BoxBrush{{0, 0, 0}, {69, 43, 65}}, 2});
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.max_distance = 12;
  DynamicDistanceField live(w, o);
  DirtyRegions dirty(16, DirtyRegions::Track::kOccupancy);
  apply_edit(w, {EditOp::kCarve, SphereBrush{{35, 22, 33}, 3}, 1}, &dirty);
  const auto stats = live.update(dirty);
  EXPECT_EQ(stats.voxels_recomputed, 7 * 7 * 7);
  EXPECT_EQ(stats.voxels_read, 9 * 9 * 9);
  expect_same_field(live.field(), compute_distance_field(w, o), bounds, 0);
  EXPECT_NEAR(live.field().distance({35, 22, 33}), std::sqrt(10.0),
              1e-6);  // to (35, 25, 32) and kin
}

// The voxels nearer a new site than to every old one need not be 26-connected on the grid (the
// discrete Voronoi cells that make propagation methods inexact). Here part of the new site's cell
// is cut off from it; the update's search for the affected box must still reach it (its rounding
// slack does: without it the box misses voxels that change). The search runs without the volume
// cap that updates give it, which would hide a miss behind a fall-back to the whole region.
TEST(DynamicField, AffectedBoxSearchReachesDisconnectedPartsOfANewSitesCell) {
  const Box3i bounds = Box3i::from_size({40, 40, 40});
  World w(16, bounds);
  w.voxels.set({6, 11, 26}, 1);
  w.voxels.set({7, 27, 23}, 1);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.domain = bounds;
  const DistanceField before = compute_distance_field(w, o);
  const Box3i placed = Box3i::from_inclusive({6, 23, 25}, {6, 23, 25});
  w.voxels.set(placed.begin, 1);
  const DistanceField after = compute_distance_field(w, o);
  const Box3i box =
      detail::grow_affected(detail::make_field_plan(w.voxels, o),
                            std::get<Grid<float>>(before.values), bounds, placed, bounds.volume());
  int changed = 0;
  for (int z = 0; z < 40; ++z)
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x)
        if (before.distance({x, y, z}) != after.distance({x, y, z})) {
          ++changed;
          ASSERT_TRUE(box.contains(Vec3i{x, y, z}))
              << "voxel " << to_string(Vec3i{x, y, z}) << " changed outside " << to_string(box);
        }
  EXPECT_GT(changed, 1000);
  EXPECT_LT(box.volume(), bounds.volume());  // the search did not just return the whole region
  // And end to end, through an update.
  World w2(16, bounds);
  w2.voxels.set({6, 11, 26}, 1);
  w2.voxels.set({7, 27, 23}, 1);
  DynamicDistanceField live(w2, o);
  DirtyRegions dirty(16, DirtyRegions::Track::kOccupancy);
  apply_edit(w2, {EditOp::kPlace, BoxBrush{placed.begin, placed.begin}, 1}, &dirty);
  live.update(dirty);
  expect_same_field(live.field(), after, bounds, 0);
}

TEST(DynamicField, UpdatesStayLocal) {
  World w(16, Box3i::from_size({128, 128, 128}));
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.max_distance = 8;
  DynamicDistanceField live(w, o);
  EXPECT_EQ(live.reach(), (Vec3i{8, 8, 8}));
  DirtyRegions dirty(16);
  apply_edit(w, {EditOp::kPlace, SphereBrush{{64, 64, 64}, 2}, 1}, &dirty);
  const auto stats = live.update(dirty);
  EXPECT_EQ(stats.regions, 1);
  EXPECT_EQ(stats.voxels_recomputed, 21 * 21 * 21);  // the 5^3 edit grown by 8 on every side
  EXPECT_EQ(stats.voxels_read, 21 * 21 * 21);  // placing only adds sites: the box's own suffice
  EXPECT_EQ(live.field().distance({64, 64, 71}), 5);
  // Carving removes sites: values may rise, and need the sites up to 8 voxels farther. Only voxels
  // whose old distance reaches the carve can change, so the recomputed box is at most the 3^3
  // carve grown by 8 — and at least every voxel whose value did change (found by full rebuilds).
  const DistanceField before = compute_distance_field(w, o);
  dirty.clear();
  apply_edit(w, {EditOp::kCarve, SphereBrush{{64, 64, 64}, 1}, 1}, &dirty);
  EXPECT_TRUE(dirty.removes_solid());
  EXPECT_FALSE(dirty.adds_solid());
  const DistanceField after = compute_distance_field(w, o);
  Box3i moved;
  for (int z = 40; z < 90; ++z)
    for (int y = 40; y < 90; ++y)
      for (int x = 40; x < 90; ++x)
        if (before.distance({x, y, z}) != after.distance({x, y, z}))
          moved = moved.unite(Box3i::from_inclusive({x, y, z}, {x, y, z}));
  ASSERT_FALSE(moved.empty());
  const auto carved = live.update(dirty);
  EXPECT_LE(carved.voxels_recomputed, 19 * 19 * 19);
  EXPECT_GE(carved.voxels_recomputed, moved.volume());
  const int side =
      static_cast<int>(std::lround(std::cbrt(static_cast<double>(carved.voxels_recomputed))));
  EXPECT_EQ(carved.voxels_recomputed, side * side * side);  // a cube, by symmetry
  // The sites: at most the box grown by 8 (less where whole chunks of it are air).
  EXPECT_LE(carved.voxels_read, (side + 16) * (side + 16) * (side + 16));
  EXPECT_GE(carved.voxels_read, carved.voxels_recomputed);
  EXPECT_EQ(live.field().distance({64, 64, 71}), 5);
  EXPECT_NEAR(live.field().distance({64, 64, 64}), std::sqrt(2.0),
              1e-6);  // to (65, 65, 64), still solid
  // Unbounded worlds without a domain are refused.
  World open;
  EXPECT_THROW(DynamicDistanceField(open, o), InvalidArgument);
}

TEST(EditStream, IsTheSameStreamOnEveryMachine) {
  // The generator is the standard's mt19937_64, specified bit for bit: its 10 000th output from
  // the default seed is given by the standard itself ([rand.predef]).
  std::mt19937_64 standard;
  standard.discard(9999);
  EXPECT_EQ(standard(), 9981545732273789042ull);
  // The first edits of `voxfield bench edits`' default stream (seed 6683787, a 256^3 world, radii
  // 1..31), as computed by an independent MT19937-64 written from Matsumoto & Nishimura's
  // published algorithm, drawing (radius, material, x, y, z) by remainder as the stream defines.
  RandomEditStream stream(Box3i::from_size({256, 256, 256}), 6683787, 1, 31);
  const struct {
    int radius, material, x, y, z;
  } want[] = {{7, 216, 81, 241, 245},
              {27, 20, 26, 220, 18},
              {12, 157, 240, 242, 206},
              {16, 244, 215, 107, 123}};
  for (const auto& w : want) {
    const Edit e = stream.next();
    const auto& s = std::get<SphereBrush>(e.brush);
    EXPECT_EQ(s.radius, w.radius);
    EXPECT_EQ(s.center, (Vec3d{static_cast<double>(w.x), static_cast<double>(w.y),
                               static_cast<double>(w.z)}));
    EXPECT_EQ(e.op, w.material == 0 ? EditOp::kCarve : EditOp::kPlace);
    EXPECT_EQ(e.material, w.material);
  }
}

TEST(UpdateRegions, CutsCoverEachRegionOnceWithTheSitesEachPartNeeds) {
  // split_regions (how a device with small buffers computes a clamped field in parts): every
  // voxel of a region's `out` lies in exactly one part, each part reads the sites within the reach
  // of its own voxels (its box grown by the reach, clipped to the domain), and each reads at most
  // the bound — or, where no cut along any axis could bring it under, the region stays whole.
  std::mt19937 rng(29);
  auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  int cut = 0, whole = 0;
  for (int round = 0; round < 300; ++round) {
    const Box3i domain{{uni(-20, 5), uni(-20, 5), uni(-20, 5)},
                       {uni(10, 70), uni(10, 70), uni(10, 40)}};
    const Vec3i reach{uni(0, 9), uni(0, 9), uni(0, 9)};
    std::vector<detail::UpdateRegion> regions;
    if (round % 3 == 0) {
      regions.push_back({domain, domain});  // a whole build
    } else {
      DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
      for (int k = uni(1, 3); k > 0; --k) {
        const Vec3i p{uni(domain.begin.x, domain.end.x - 1), uni(domain.begin.y, domain.end.y - 1),
                      uni(domain.begin.z, domain.end.z - 1)};
        dirty.add(Box3i{p, p + Vec3i{uni(1, 12), uni(1, 12), uni(1, 12)}}.intersect(domain));
      }
      regions = detail::update_regions(dirty, domain, reach);
    }
    const std::int64_t most = uni(1, 40000);
    for (const detail::UpdateRegion& r : regions) {
      const std::vector<detail::UpdateRegion> parts =
          detail::split_regions({r}, domain, reach, most);
      ASSERT_FALSE(parts.empty());
      if (r.in.volume() <= most) {
        ASSERT_EQ(parts.size(), 1u);
        EXPECT_EQ(parts[0].out, r.out);
        EXPECT_EQ(parts[0].in, r.in);
        continue;
      }
      std::int64_t covered = 0;
      for (std::size_t i = 0; i < parts.size(); ++i) {
        const detail::UpdateRegion& p = parts[i];
        EXPECT_FALSE(p.out.empty());
        EXPECT_EQ(p.out.intersect(r.out), p.out);
        for (std::size_t j = 0; j < i; ++j) EXPECT_TRUE(p.out.intersect(parts[j].out).empty());
        EXPECT_EQ(p.in, (Box3i{p.out.begin - reach, p.out.end + reach}).intersect(domain));
        covered += p.out.volume();
      }
      EXPECT_EQ(covered, r.out.volume());
      if (parts.size() > 1) {
        ++cut;
        for (const auto& p : parts) EXPECT_LE(p.in.volume(), most);
      } else {
        ++whole;
        // Left whole: even a slab one voxel thick along any axis reads more than the bound.
        for (int a = 0; a < 3; ++a)
          EXPECT_GT(std::min(1 + 2 * reach[a], r.in.size()[a]) * (r.in.volume() / r.in.size()[a]),
                    most);
      }
    }
  }
  EXPECT_GT(cut, 20);  // both outcomes occur
  EXPECT_GT(whole, 20);
}
