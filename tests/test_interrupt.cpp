// Progress and cancellation (voxfield/interrupt.h): long operations report their work to an
// Interrupter from their worker threads, and stop with Cancelled — their inputs untouched — when it
// asks.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <vector>

#include "voxfield/algorithms.h"
#include "voxfield/distance.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/edit.h"
#include "voxfield/interrupt.h"
#include "voxfield/mesh.h"
#include "voxfield/parallel.h"
#include "voxfield/render.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

// Records what it is told; cancels once progress reaches `cancel_at` percent (never when > 100).
class Recorder : public Interrupter {
 public:
  explicit Recorder(int cancel_at = 101) : cancel_at_(cancel_at) {}
  void start(std::string_view name) override {
    std::lock_guard lock(mutex_);
    names.emplace_back(name);
    ++starts;
  }
  void end() override { ++ends; }
  bool was_interrupted(int percent) override {
    std::lock_guard lock(mutex_);
    percents.push_back(percent);
    return percent >= cancel_at_;
  }
  std::vector<std::string> names;
  std::vector<int> percents;
  std::atomic<int> starts{0}, ends{0};

 private:
  int cancel_at_;
  std::mutex mutex_;
};

// Counts the questions it is asked; cancels at the `cancel_at`-th (never when 0).
class Questions : public Interrupter {
 public:
  explicit Questions(int cancel_at = 0) : cancel_at_(cancel_at) {}
  bool was_interrupted(int) override { return ++asked == cancel_at_; }
  std::atomic<int> asked{0};

 private:
  int cancel_at_;
};

}  // namespace

TEST(Interrupt, ProgressCountsUnitsAndReachesAHundred) {
  Recorder r;
  {
    Progress p(&r, "units", 8);
    for (int i = 0; i < 8; ++i) EXPECT_TRUE(p.advance());
    EXPECT_NO_THROW(p.throw_if_cancelled());
  }
  EXPECT_EQ(r.names, std::vector<std::string>{"units"});
  EXPECT_EQ(r.starts, 1);
  EXPECT_EQ(r.ends, 1);
  // 0 at the start, then 12, 25, ... as units finish (integer percent of 8 units).
  EXPECT_EQ(r.percents, (std::vector<int>{0, 12, 25, 37, 50, 62, 75, 87, 100}));
}

TEST(Interrupt, ANullInterrupterNeverCancels) {
  Progress p(nullptr, "nothing watches", 3);
  EXPECT_TRUE(p.advance(5));
  EXPECT_TRUE(p.keep_going());
  EXPECT_FALSE(p.cancelled());
}

TEST(Interrupt, CancellingStopsSceneGenerationWithCancelled) {
  SceneOptions o;
  o.size = {128, 128, 64};
  o.chunk_edge = 16;
  Recorder r(/*cancel_at=*/30);
  try {
    make_terrain(o, &r);
    FAIL() << "make_terrain finished although cancelled";
  } catch (const Cancelled& e) {
    EXPECT_NE(std::string(e.what()).find("terrain scene"), std::string::npos) << e.what();
  }
  EXPECT_EQ(r.ends, 1);  // end() is called on the way out of a cancelled operation too
  // The generator stopped asking soon after it was told to stop (a few chunks in flight per
  // thread).
  int asked_after = 0;
  for (int p : r.percents) asked_after += p > 40;
  EXPECT_LT(asked_after, 8);

  Recorder watch;  // the same operation, watched but not cancelled, gives the plain result
  const World watched = make_terrain(o, &watch);
  EXPECT_EQ(watched.solid_count(), make_terrain(o).solid_count());
  EXPECT_EQ(watch.percents.back(), 100);
}

TEST(Interrupt, CancellingARenderThrowsAndAWatchedRenderIsUnchanged) {
  SceneOptions so;
  so.size = {64, 64, 64};
  const World w = make_terrain(so);
  const RenderScene scene(w);
  const Camera camera = Camera::framing(Box3i::from_size(so.size), 4.0 / 3.0);
  RenderOptions o;
  o.width = 96;
  o.height = 72;
  o.tile_size = 8;  // 12 x 9 tiles
  Recorder cancel(/*cancel_at=*/50);
  EXPECT_THROW(render(scene, camera, o, nullptr, &cancel), Cancelled);
  Recorder watch;
  const Image watched = render(scene, camera, o, nullptr, &watch);
  EXPECT_EQ(watched.rgb, render(scene, camera, o).rgb);
  EXPECT_EQ(watch.names, std::vector<std::string>{"render"});
  EXPECT_EQ(watch.percents.size(), 12u * 9u + 1u);  // one question per tile, and one at the start
  EXPECT_EQ(watch.percents.back(), 100);
}

// The exact transform reports its columns and slices (both its paths: the envelope and the
// truncated min-convolution) and stops when asked, returning nothing; the result of an
// uninterrupted run with an interrupter equals one without.
TEST(Interrupt, ExactFieldsReportProgressAndCancel) {
  SceneOptions so;
  so.size = Vec3i::splat(64);
  const World w = make_terrain(so);
  for (double clamp : {0.0, 8.0}) {
    SCOPED_TRACE(clamp);
    DistanceOptions o;
    o.metric = Metric::kEuclidean;
    o.max_distance = clamp;
    const DistanceField plain = compute_distance_field(w, o);
    Recorder r;
    o.interrupter = &r;
    const DistanceField watched = compute_distance_field(w, o);
    EXPECT_EQ(r.names, std::vector<std::string>{"exact distance field"});
    EXPECT_EQ(r.ends, 1);
    ASSERT_FALSE(r.percents.empty());
    EXPECT_EQ(r.percents.back(), 100);
    for (int z = 0; z < 64; z += 7)
      for (int x = 0; x < 64; x += 5)
        EXPECT_EQ(watched.distance({x, 11, z}), plain.distance({x, 11, z}));
    Recorder stop(30);
    o.interrupter = &stop;
    EXPECT_THROW(compute_distance_field(w, o), Cancelled);
    EXPECT_EQ(stop.ends, 1);
  }
}

TEST(Interrupt, TheAlgorithmFamilyReportsAndCancelsBetweenPasses) {
  SceneOptions so;
  so.size = Vec3i::splat(40);
  const World w = make_terrain(so);
  for (Algorithm alg : {Algorithm::kJfa, Algorithm::kJfa2, Algorithm::kJfaSeed, Algorithm::kFim,
                        Algorithm::kHybrid, Algorithm::kLod, Algorithm::kBruteChunked}) {
    SCOPED_TRACE(algorithm_name(alg));
    DistanceOptions o;
    o.metric = Metric::kManhattan;
    o.signed_distance = alg == Algorithm::kJfa;  // two solves, one per sign
    AlgorithmOptions a;
    a.algorithm = alg;
    if (alg == Algorithm::kLod) a.focus = Box3i{{8, 8, 8}, {20, 20, 20}};
    const DistanceField plain = compute_distance_field(w, o, a);
    Recorder r;
    o.interrupter = &r;
    const DistanceField watched = compute_distance_field(w, o, a);
    EXPECT_EQ(r.names,
              std::vector<std::string>{std::string(algorithm_name(alg)) + " distance field"});
    EXPECT_EQ(r.ends, 1);
    ASSERT_FALSE(r.percents.empty());
    EXPECT_EQ(r.percents.back(), 100);
    EXPECT_EQ(watched.options.interrupter, nullptr) << "the field never keeps the interrupter";
    for (int z = 0; z < 40; z += 3)
      for (int x = 0; x < 40; x += 3)
        ASSERT_EQ(watched.distance({x, 13, z}), plain.distance({x, 13, z}));
    Recorder stop(0);  // at the first question, when it starts
    o.interrupter = &stop;
    EXPECT_THROW(compute_distance_field(w, o, a), Cancelled);
    EXPECT_EQ(stop.ends, 1);
    // The solvers ask between their passes: more questions than the start and the three units
    // (the serial ones once per pass, brute-chunked once per block of chunks)...
    Questions count;
    o.interrupter = &count;
    AlgorithmStats st;
    compute_distance_field(w, o, a, &st);
    EXPECT_GT(count.asked.load(), 4) << st.passes << " passes, " << st.iterations << " iterations";
    // ... and one cancelled at the first of those stops there: the serial loops ask no more.
    Questions cut(2);
    o.interrupter = &cut;
    EXPECT_THROW(compute_distance_field(w, o, a), Cancelled);
    if (alg != Algorithm::kBruteChunked) {
      EXPECT_EQ(cut.asked.load(), 2);
    }
  }
}

TEST(Interrupt, RebuildsReportAndCancelKeepingTheFieldTheyHad) {
  SceneOptions so;
  so.size = Vec3i::splat(48);
  World w = make_terrain(so);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.max_distance = 6;
  DynamicDistanceField live(w, o);
  const DistanceField before = live.field();
  apply_edit(w, Edit{EditOp::kCarve, SphereBrush{{24, 24, 10}, 9}, 1});
  Recorder stop(0);
  EXPECT_THROW(live.rebuild(&stop), Cancelled);
  for (int z = 0; z < 48; z += 2)
    for (int x = 0; x < 48; x += 2)
      ASSERT_EQ(live.field().distance({x, 24, z}), before.distance({x, 24, z}));
  Recorder r;
  live.rebuild(&r);
  EXPECT_EQ(r.names, std::vector<std::string>{"exact distance field"});
  EXPECT_EQ(r.percents.back(), 100);
  EXPECT_EQ(live.field().options.interrupter, nullptr);
  const DistanceField fresh = compute_distance_field(w, live.options());
  for (int z = 0; z < 48; z += 2)
    for (int x = 0; x < 48; x += 2)
      ASSERT_EQ(live.field().distance({x, 24, z}), fresh.distance({x, 24, z}));
}

TEST(Interrupt, MeshingReportsChunksAndCancels) {
  std::vector<float> v(40 * 40 * 40);
  for (int z = 0; z < 40; ++z)
    for (int y = 0; y < 40; ++y)
      for (int x = 0; x < 40; ++x)
        v[static_cast<std::size_t>(x + 40 * (y + 40 * z))] = static_cast<float>(z - 20 + 0.3 * x);
  ScalarVolume vol{Vec3i::splat(40), v.data()};
  MeshOptions o;
  o.chunk_edge = 8;
  Recorder r;
  o.interrupter = &r;
  EXPECT_GT(mesh_volume(vol, o).triangle_count(), 0u);
  EXPECT_EQ(r.names, std::vector<std::string>{"marching cubes"});
  EXPECT_EQ(r.percents.back(), 100);
  Recorder stop(40);
  o.interrupter = &stop;
  EXPECT_THROW(mesh_volume(vol, o), Cancelled);
}

// Questions from many threads reach the interrupter one at a time with percentages that never
// decrease, ending at 100 (a progress bar never steps back).
TEST(Interrupt, ProgressFromManyThreadsNeverStepsBack) {
  for (int round = 0; round < 20; ++round) {
    Recorder r;
    {
      Progress p(&r, "many", 4000);
      parallel_for(4000, 1, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) p.advance();
      });
    }
    ASSERT_FALSE(r.percents.empty());
    EXPECT_TRUE(std::is_sorted(r.percents.begin(), r.percents.end())) << "round " << round;
    EXPECT_EQ(r.percents.back(), 100) << "round " << round;
  }
}
