// LiveWorld under concurrency: edits submitted from several threads while another thread updates
// and readers keep checking that every snapshot is consistent (the field is exactly the field of
// the world it is shown with, and a kept mesh exactly its mesh). Run under ThreadSanitizer by
// scripts/test.sh (preset tsan).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <random>
#include <thread>

#include "mesh_compare.h"
#include "voxfield/live_world.h"

using namespace voxfield;

namespace {

constexpr int kClamp = 4;

// Exact clamped Manhattan distance at p by scanning the clamp's neighbourhood: the oracle a
// reader applies to each snapshot.
double manhattan_at(const World& w, Vec3i p, const Box3i& bounds) {
  if (w.voxels.get(p) != 0) return 0;
  double best = kClamp;
  for (int dz = -kClamp; dz <= kClamp; ++dz)
    for (int dy = -kClamp; dy <= kClamp; ++dy)
      for (int dx = -kClamp; dx <= kClamp; ++dx) {
        const Vec3i q = p + Vec3i{dx, dy, dz};
        if (!bounds.contains(q) || w.voxels.get(q) == 0) continue;
        best = std::min<double>(best, std::abs(dx) + std::abs(dy) + std::abs(dz));
      }
  return best;
}

}  // namespace

TEST(LiveWorld, ConcurrentEditsUpdatesAndReadersStayConsistent) {
  const Box3i bounds = Box3i::from_size({48, 40, 32});
  DistanceOptions o;
  o.metric = Metric::kManhattan;
  o.max_distance = kClamp;
  LiveWorld live(World(16, bounds), o);
  constexpr int kWriters = 3, kEditsEach = 150;
  std::atomic<int> writers_done{0};
  std::atomic<bool> stop_readers{false};
  std::atomic<int> snapshots{0}, inconsistent{0};
  std::atomic<int> batches{0};

  std::vector<std::thread> threads;
  for (int t = 0; t < kWriters; ++t) {
    threads.emplace_back([&, t] {
      std::mt19937 rng(100 + t);
      for (int i = 0; i < kEditsEach; ++i) {
        Edit e;
        e.op = rng() % 3 == 0 ? EditOp::kCarve : EditOp::kPlace;
        e.material = static_cast<std::uint8_t>(1 + rng() % 9);
        e.brush = SphereBrush{{static_cast<double>(rng() % 48), static_cast<double>(rng() % 40),
                               static_cast<double>(rng() % 32)},
                              static_cast<double>(1 + rng() % 4)};
        live.submit(e);
        // Spread the submissions out so that they interleave with many updates; and at two points
        // wait for the updater to have applied a batch, so that edits arrive during updates
        // however the threads are scheduled (under ThreadSanitizer a first update could outlast
        // every writer's sleeps).
        if (i % 5 == 4) std::this_thread::sleep_for(std::chrono::milliseconds(2));
        if (i == 50 || i == 100)
          while (batches.load() < i / 50) std::this_thread::yield();
      }
      ++writers_done;
    });
  }
  threads.emplace_back([&] {  // the updater
    while (writers_done.load() < kWriters || live.pending() > 0) batches += live.update().edits > 0;
  });
  for (int r = 0; r < 2; ++r) {
    threads.emplace_back([&, r] {
      std::mt19937 rng(7 + r);
      while (!stop_readers.load()) {
        live.read([&](const World& w, const DistanceField& f) {
          for (int k = 0; k < 20; ++k) {
            const Vec3i p{static_cast<int>(rng() % 48), static_cast<int>(rng() % 40),
                          static_cast<int>(rng() % 32)};
            if (f.distance(p) != manhattan_at(w, p, bounds)) ++inconsistent;
          }
          return 0;
        });
        ++snapshots;
      }
    });
  }
  for (int t = 0; t <= kWriters; ++t)
    threads[static_cast<std::size_t>(t)].join();  // writers and updater
  stop_readers = true;
  for (std::size_t t = kWriters + 1; t < threads.size(); ++t) threads[t].join();
  EXPECT_EQ(live.pending(), 0u);
  EXPECT_GE(batches.load(), 3);  // edits really arrived while updates ran
  EXPECT_GT(snapshots.load(), 0);
  EXPECT_EQ(inconsistent.load(), 0);
  // In the end: exactly the field of the final world.
  live.read([&](const World& w, const DistanceField& f) {
    const DistanceField full = compute_distance_field(w, o);
    for (int z = 0; z < 32; ++z)
      for (int y = 0; y < 40; ++y)
        for (int x = 0; x < 48; ++x) EXPECT_EQ(f.distance({x, y, z}), full.distance({x, y, z}));
    return 0;
  });
  // Bad edits are refused in the submitting thread.
  EXPECT_THROW(live.submit({EditOp::kPlace, SphereBrush{{0, 0, 0}, -2}, 1}), InvalidArgument);
}

// A kept mesh through concurrent edits: every snapshot a reader takes has the mesh of exactly the
// world it is shown with (mesh_world's triangles), and updates say which chunks they re-meshed.
TEST(LiveWorld, KeptMeshFollowsConcurrentEdits) {
  const Box3i bounds = Box3i::from_size({40, 32, 24});
  World start(8, bounds);
  start.voxels.fill(Box3i{{0, 0, 0}, {40, 32, 6}}, 2);  // a floor touching the bounds
  DistanceOptions o;
  o.metric = Metric::kManhattan;
  o.max_distance = kClamp;
  LiveWorld live(std::move(start), o);
  EXPECT_THROW(live.read_mesh([](const World&, const WorldMeshChunks&) { return 0; }),
               InvalidArgument);
  MeshOptions mo;
  mo.algorithm = Mesher::kSurfaceNets;
  mo.chunk_edge = 8;
  live.keep_mesh(mo);
  constexpr int kWriters = 2, kEditsEach = 40;
  std::atomic<int> writers_done{0}, remeshed{0}, snapshots{0}, inconsistent{0};
  std::atomic<bool> stop_reader{false};
  std::vector<std::thread> threads;
  for (int t = 0; t < kWriters; ++t)
    threads.emplace_back([&, t] {
      std::mt19937 rng(300 + t);
      for (int i = 0; i < kEditsEach; ++i) {
        Edit e;
        e.op = i % 3 == 0 ? EditOp::kCarve : i % 3 == 1 ? EditOp::kPlace : EditOp::kPaint;
        e.material = static_cast<std::uint8_t>(1 + rng() % 9);
        e.brush = SphereBrush{{static_cast<double>(rng() % 40), static_cast<double>(rng() % 32),
                               static_cast<double>(rng() % 12)},
                              static_cast<double>(1 + rng() % 3)};
        live.submit(e);
        if (i % 4 == 3) std::this_thread::sleep_for(std::chrono::milliseconds(3));
      }
      ++writers_done;
    });
  threads.emplace_back([&] {  // the updater
    while (writers_done.load() < kWriters || live.pending() > 0)
      remeshed += static_cast<int>(live.update().remeshed_chunks.size());
  });
  threads.emplace_back([&] {  // a reader comparing each snapshot's mesh with its world's
    while (!stop_reader.load()) {
      live.read_mesh([&](const World& w, const WorldMeshChunks& mesh) {
        if (test::corner_triangles<true>(mesh.merged()) !=
            test::corner_triangles<true>(mesh_world(w, mo)))
          ++inconsistent;
        return 0;
      });
      ++snapshots;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  });
  for (int t = 0; t <= kWriters; ++t) threads[static_cast<std::size_t>(t)].join();
  stop_reader = true;
  threads.back().join();
  EXPECT_GT(snapshots.load(), 0);
  EXPECT_EQ(inconsistent.load(), 0);
  EXPECT_GT(remeshed.load(), 0);
  live.read_mesh([&](const World& w, const WorldMeshChunks& mesh) {
    EXPECT_TRUE(test::corner_triangles<true>(mesh.merged()) ==
                test::corner_triangles<true>(mesh_world(w, mo)));
    return 0;
  });
}
