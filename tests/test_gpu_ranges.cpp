// Work past what one storage-buffer binding may cover (maxStorageBufferRange: 128 MiB on
// lavapipe), on contexts whose range is lowered (test::capped_context) so that small inputs take
// the same paths: clamped fields computed in slabs, and large buffers bound as four windows
// (src/gpu/split_buffer.h) — the world's brick pool, a field and its nearest sites, the algorithm
// family's ping-pong buffers — each equal to the CPU's field or to a device binding everything
// whole; what does not fit refused by name before anything is uploaded. The validation layer is
// on and says nothing.
#include <gtest/gtest.h>

#include "gpu_fields.h"
#include "gpu_suite.h"
#include "voxfield/edit.h"
#include "voxfield/gpu_distance.h"

using namespace voxfield;
using test::dense;
using test::expect_same_field;
using test::gpu_tests_wanted;
using test::random_world;
using test::validated_context;

TEST(Gpu, FieldsBeyondTheStorageBufferRangeAreComputedInParts) {
  // The exact transform's work buffers hold 4 bytes per voxel of a region (24 more with nearest
  // sites). On a device whose storage-buffer range cannot bind them (lowered here through
  // ContextOptions, as a user sharing a device would), a clamped field is computed in slabs, each
  // with the sites within its reach, and any field in z-slabs with each column's nearest sites
  // beyond them: the same bits as the CPU's, builds and updates alike, with more dispatches. Where
  // not even one z-slice fits, the field is refused with InvalidArgument before anything is
  // uploaded, instead of binding past the range.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  // 16 383 voxels a binding: one short of the whole domain.
  // (Named, not structured, bindings: the lambdas below capture them, which Clang 14 refuses.)
  const test::CappedAndWhole contexts = test::capped_and_whole(64 * 1024 - 4);
  const std::shared_ptr<gpu::Context>& small = contexts.small;
  const std::shared_ptr<gpu::Context>& whole = contexts.whole;
  World w = random_world({32, 32, 16}, 8, 0.01, 4);  // 16 384 voxels: 64 KiB per cost buffer
  w.voxels.set(Vec3i{31, 31, 15}, 2);  // a site in the last corner: a slab's edge is crossed
  DistanceOptions o;
  o.storage = Storage::kU8;
  o.max_distance = 6;
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool is_signed : {false, true}) {
      o.metric = m;
      o.signed_distance = is_signed;
      const std::string what = std::string(metric_name(m)) + (is_signed ? " signed" : "");
      const std::int64_t before = small->counters().dispatches;
      const DistanceField parts = gpu::compute_distance_field(*small, w, o);
      const std::int64_t in_parts = small->counters().dispatches - before;
      const std::int64_t before_whole = whole->counters().dispatches;
      expect_same_field(parts, gpu::compute_distance_field(*whole, w, o), what);
      expect_same_field(parts, compute_distance_field(w, o), what);
      EXPECT_GT(in_parts, whole->counters().dispatches - before_whole) << what;
      // An update whose region is the whole domain (a box edit across it), then a small one.
      World edited = w;
      gpu::DynamicField live(small, edited, o);
      DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
      apply_edit(edited, Edit{EditOp::kPlace, BoxBrush{{2, 3, 4}, {30, 29, 12}}, 3}, &dirty);
      live.update(dirty);
      dirty.clear();
      apply_edit(edited, Edit{EditOp::kCarve, SphereBrush{{16, 16, 8}, 5}, 0}, &dirty);
      live.update(dirty);
      expect_same_field(live.download(), compute_distance_field(edited, o), what + ", edited");
    }
  // Nearly every chunk holding voxels: the world's brick pool (512 bytes a chunk) reaches into the
  // last of the four 32 KiB windows the passes bind it in (src/gpu/split_buffer.h), and so does
  // the u8 field (125 440 bytes).
  const World dense = random_world({56, 56, 40}, 8, 0.3, 6);
  std::size_t bricks = 0;
  for (int z = 0; z < 5; ++z)
    for (int y = 0; y < 7; ++y)
      for (int x = 0; x < 7; ++x) bricks += dense.voxels.chunk_view({x, y, z}).voxels != nullptr;
  ASSERT_GT(bricks * 512, 3u * 32 * 1024) << "the live bricks reach the fourth window";
  ASSERT_LE(bricks * 512, 4u * 32 * 1024);
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.max_distance = 2;  // slabs of 3 slices, each reading 2 more on either side
  expect_same_field(gpu::compute_distance_field(*small, dense, o), compute_distance_field(dense, o),
                    "every chunk holding voxels");
  // The field and its nearest sites are resident whole, bound in windows too: an f32 field of
  // 64 KiB (two windows) and the sites of a 64x16x16 domain, 128 KiB (all four), built and
  // updated, while the passes' work buffers go in slabs.
  {
    World long_world = random_world({64, 16, 16}, 8, 0.01, 8);
    DistanceOptions f = o;
    f.storage = Storage::kF32;
    f.nearest_sites = true;
    expect_same_field(gpu::compute_distance_field(*small, long_world, f),
                      compute_distance_field(long_world, f), "f32 with nearest sites in windows");
    gpu::DynamicField live(small, long_world, f);
    DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
    apply_edit(long_world, Edit{EditOp::kPlace, SphereBrush{{50, 8, 8}, 4}, 5}, &dirty);
    live.update(dirty);
    expect_same_field(live.download(), compute_distance_field(long_world, f),
                      "f32 with nearest sites in windows, edited");
  }
  // Where no slab with halos fits — an unclamped field, whose reach is the whole domain, or the
  // sites' work buffers (24 bytes a voxel) — a region is cut into z-slabs whose z passes start each
  // column from its nearest sites beyond the slab (edt_columns, column_slabs.h): the CPU's bits,
  // built and updated, at more dispatches.
  o.max_distance = 0;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.storage = Storage::kU16;
  {
    const std::int64_t before = small->counters().dispatches;
    expect_same_field(gpu::compute_distance_field(*small, w, o), compute_distance_field(w, o),
                      "unclamped, in z-slabs");
    const std::int64_t in_slabs = small->counters().dispatches - before;
    const std::int64_t before_whole = whole->counters().dispatches;
    (void)gpu::compute_distance_field(*whole, w, o);
    EXPECT_GT(in_slabs, whole->counters().dispatches - before_whole);
    World edited = w;
    gpu::DynamicField live(small, edited, o);
    DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
    apply_edit(edited, Edit{EditOp::kCarve, BoxBrush{{0, 0, 0}, {12, 12, 6}}, 0}, &dirty);
    apply_edit(edited, Edit{EditOp::kPlace, SphereBrush{{20, 24, 12}, 3}, 2}, &dirty);
    live.update(dirty);
    expect_same_field(live.download(), compute_distance_field(edited, o),
                      "unclamped, in z-slabs, edited");
  }
  {
    World shorter = random_world({32, 32, 12}, 8, 0.02, 12);  // slabs of 2 slices with sites
    DistanceOptions f = o;
    f.metric = Metric::kManhattan;
    f.storage = Storage::kF32;
    f.nearest_sites = true;
    expect_same_field(gpu::compute_distance_field(*small, shorter, f),
                      compute_distance_field(shorter, f), "unclamped with sites, in z-slabs");
  }
  // A clamp too wide for halos (20 voxels on a 32 x 32 x 64 world) takes the z-slabs too; an
  // update's region then reads more slices than it writes, and the slabs holding none of the
  // voxels it writes are skipped (their sites reach the others through the column neighbours).
  {
    World deep = random_world({32, 32, 64}, 8, 0.01, 14);
    DistanceOptions f;
    f.metric = Metric::kEuclidean;
    f.max_distance = 20;
    f.storage = Storage::kU8;
    // The build: the slab neighbours, then five slabs of 15 slices (z, x and y passes, encode).
    const std::int64_t d0 = small->counters().dispatches;
    gpu::DynamicField live(small, deep, f);
    EXPECT_EQ(small->counters().dispatches - d0, 1 + 5 * 4);
    expect_same_field(live.download(), compute_distance_field(deep, f), "clamp 20, in z-slabs");
    DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
    apply_edit(deep, Edit{EditOp::kPlace, SphereBrush{{10, 20, 3}, 2}, 4}, &dirty);
    // The update writes z 0..26 and reads z 0..46: of its four slabs the last two write nothing.
    const std::int64_t d1 = small->counters().dispatches;
    const DynamicDistanceField::UpdateStats st = live.update(dirty);
    EXPECT_EQ(small->counters().dispatches - d1, 1 + 2 * 4);
    EXPECT_LT(st.voxels_recomputed, st.voxels_read);
    expect_same_field(live.download(), compute_distance_field(deep, f),
                      "clamp 20, in z-slabs, edited");
  }
  // Not even one z-slice fits (160 x 128 voxels, 80 KiB a cost buffer; the u8 field fits its
  // windows): refused by name before anything is uploaded.
  const World wide = random_world({160, 128, 4}, 8, 0.01, 13);
  o.storage = Storage::kU8;
  const gpu::Counters before = small->counters();
  try {
    gpu::DynamicField refused(small, wide, o);
    ADD_FAILURE() << "an unclamped field whose slices pass the storage-buffer range was made";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("and so does one z-slice of it (160 x 128 voxels)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(small->counters().bytes_uploaded, before.bytes_uploaded);  // nothing was uploaded
  test::expect_no_validation_messages(*small);
}

TEST(Gpu, FamilyPingPongBuffersPastTheRangeAreBoundInWindows) {
  // Jump flooding and FIM keep both halves of their ping-pong in one buffer: 16 bytes a voxel for
  // JFA's sites, 8 for jfa-seed's and FIM's values. On a device whose storage-buffer range is
  // below that (lowered through ContextOptions) the passes bind it as four windows
  // (src/gpu/split_buffer.h): the fields equal a device's that binds it whole, bit for bit (the
  // same shaders; the tests above hold those to the CPU). Past four windows the algorithm is
  // refused by name.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  // Windows of 64 KiB, 256 KiB in four.
  const test::CappedAndWhole contexts = test::capped_and_whole(128 * 1024 - 4);
  const std::shared_ptr<gpu::Context>& small = contexts.small;
  const std::shared_ptr<gpu::Context>& whole = contexts.whole;
  // 14 400 voxels: JFA's ping-pong 230 400 bytes (four windows); 28 800 voxels: the values'
  // ping-pong of jfa-seed and FIM, 8 bytes a voxel, as large.
  const World w = random_world({30, 24, 20}, 8, 0.004, 61);
  const World w8 = random_world({40, 30, 24}, 8, 0.004, 63);
  struct Case {
    Algorithm algorithm;
    const World* world;
  };
  for (const Case& k :
       {Case{Algorithm::kJfa, &w}, Case{Algorithm::kJfa1, &w}, Case{Algorithm::kHybrid, &w},
        Case{Algorithm::kLod, &w}, Case{Algorithm::kJfaSeed, &w8}, Case{Algorithm::kFim, &w8}})
    for (Metric m : {Metric::kManhattan, Metric::kEuclidean}) {
      DistanceOptions o;
      o.metric = m;
      o.signed_distance = true;
      o.storage = Storage::kF32;
      AlgorithmOptions a;
      a.algorithm = k.algorithm;
      a.focus = Box3i{{8, 8, 4}, {20, 16, 12}};  // LOD's FIM region
      const std::string what = std::string(algorithm_name(k.algorithm)) + " " + metric_name(m);
      const DistanceField windows = gpu::compute_distance_field(*small, *k.world, o, a);
      const DistanceField bound_whole = gpu::compute_distance_field(*whole, *k.world, o, a);
      EXPECT_EQ(dense<float>(windows), dense<float>(bound_whole)) << what;
    }
  // A range below a palette's 4 KiB (bound whole) or the device's offset alignment (windows begin
  // at multiples of a power of two within the range) is refused.
  EXPECT_THROW(test::capped_context(4095), InvalidArgument);
  const World big = random_world({40, 30, 20}, 8, 0.004, 62);  // 24 000 voxels: 384 000 bytes
  AlgorithmOptions jfa;
  jfa.algorithm = Algorithm::kJfa;
  try {
    (void)gpu::compute_distance_field(*small, big, DistanceOptions{}, jfa);
    ADD_FAILURE() << "a ping-pong buffer past four windows was bound";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("more than this device binds"), std::string::npos)
        << e.what();
  }
  test::expect_no_validation_messages(*small);
  test::expect_no_validation_messages(*whole);
}

TEST(Gpu, UpdatesRecycleTheirDescriptorPools) {
  // The exact transform's passes bind 20 buffers (the pool, the field and its sites in windows):
  // their sets come from the shared arena's recycled pool update after update, not from a pool
  // made and destroyed for each.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  World w = random_world({40, 32, 24}, 8, 0.004, 71);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.max_distance = 5;
  o.nearest_sites = true;
  gpu::DynamicField live(ctx, w, o);
  DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
  const auto edit = [&](int i) {
    apply_edit(w, Edit{EditOp::kPlace, SphereBrush{{5.0 + 3 * i, 16, 12}, 2}, 4}, &dirty);
    live.update(dirty);
    dirty.clear();
  };
  edit(0);
  const std::int64_t pools = ctx->counters().descriptor_pools;
  for (int i = 1; i < 10; ++i) edit(i);
  EXPECT_EQ(ctx->counters().descriptor_pools, pools) << "sets recycled, no new pools";
  expect_same_field(live.download(), compute_distance_field(w, o), "after the updates");
}
