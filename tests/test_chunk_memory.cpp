// The cache of chunk voxel arrays (voxfield/chunk_memory.h): freed arrays come back to the next
// request of their size, up to the limit and no further; the limit's changes hand back what no
// longer fits; threads allocating and freeing at once never share an array; grids refuse arrays
// of the wrong size; and a field computed into reused memory equals one computed into fresh.
// (Lives in voxfield_concurrency_tests, which the ThreadSanitizer build runs.)
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <random>
#include <set>
#include <thread>
#include <vector>

#include "voxfield/chunk_memory.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/grid.h"

using namespace voxfield;

namespace {

// Sets a limit for one test and puts the process's back afterwards.
class CacheLimit {
 public:
  explicit CacheLimit(std::uint64_t bytes) : saved_(chunk_cache_limit()) {
    trim_chunk_cache();
    set_chunk_cache_limit(bytes);
  }
  ~CacheLimit() { set_chunk_cache_limit(saved_); }

 private:
  std::uint64_t saved_;
};

}  // namespace

TEST(ChunkMemory, AFreedArrayServesTheNextRequestOfItsSize) {
  const CacheLimit limit(1 << 20);
  const ChunkMemoryStats before = chunk_memory_stats();
  void* first = nullptr;
  {
    ChunkArray<float> a = make_chunk_array<float>(4096);
    first = a.get();
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(first) % 64, 0u);
    a[4095] = 1.5f;
  }
  EXPECT_EQ(chunk_memory_stats().cached_bytes, 4096u * sizeof(float));
  ChunkArray<std::uint8_t> other_size = make_chunk_array<std::uint8_t>(4096);
  EXPECT_NE(static_cast<void*>(other_size.get()), first);  // another size: not that array
  ChunkArray<std::uint32_t> same_size = make_chunk_array<std::uint32_t>(4096);
  EXPECT_EQ(static_cast<void*>(same_size.get()), first);
  const ChunkMemoryStats after = chunk_memory_stats();
  EXPECT_EQ(after.reused, before.reused + 1);
  EXPECT_EQ(after.allocated, before.allocated + 2);
  EXPECT_EQ(after.cached_bytes, 0u);
  EXPECT_EQ(after.limit_bytes, 1u << 20);
}

TEST(ChunkMemory, TheCacheNeverHoldsMoreThanItsLimit) {
  const CacheLimit limit(10 * 1000);
  {
    std::vector<ChunkArray<std::uint8_t>> arrays;
    for (int i = 0; i < 25; ++i) arrays.push_back(make_chunk_array<std::uint8_t>(1000));
  }  // 25 000 bytes freed: 10 000 kept, the rest handed back
  EXPECT_EQ(chunk_memory_stats().cached_bytes, 10u * 1000);
  set_chunk_cache_limit(3500);  // lowering the limit hands back what no longer fits
  EXPECT_EQ(chunk_memory_stats().cached_bytes, 3000u);
  trim_chunk_cache();
  EXPECT_EQ(chunk_memory_stats().cached_bytes, 0u);
  EXPECT_EQ(chunk_cache_limit(), 3500u);  // trimming keeps the limit

  set_chunk_cache_limit(0);  // disabled: nothing is kept, nothing is reused
  const ChunkMemoryStats before = chunk_memory_stats();
  for (int i = 0; i < 5; ++i) make_chunk_array<std::uint8_t>(1000).reset();
  EXPECT_EQ(chunk_memory_stats().cached_bytes, 0u);
  EXPECT_EQ(chunk_memory_stats().reused, before.reused);
}

TEST(ChunkMemory, ThreadsAllocatingAndFreeingAtOnceNeverShareAnArray) {
  const CacheLimit limit(64 << 10);  // small: some frees are kept, some handed back
  const std::uint64_t reused_before = chunk_memory_stats().reused;
  constexpr int kThreads = 4, kRounds = 3000;
  std::vector<std::thread> threads;
  std::vector<int> corrupted(kThreads, 0);
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([t, &corrupted] {
      std::mt19937 rng(static_cast<unsigned>(t) + 1);
      std::vector<ChunkArray<std::uint32_t>> held;
      std::vector<std::uint32_t> marks;  // what this thread wrote into each held array
      for (int round = 0; round < kRounds; ++round) {
        const std::size_t n = std::size_t{256} << (rng() % 3);
        ChunkArray<std::uint32_t> a = make_chunk_array<std::uint32_t>(n);
        const std::uint32_t mark = static_cast<std::uint32_t>(t * kRounds + round);
        for (std::size_t i = 0; i < n; ++i) a[i] = mark;
        held.push_back(std::move(a));
        marks.push_back(mark);
        if (held.size() > 8 || rng() % 3 == 0) {
          // Before freeing, the array must still hold this thread's mark: no other thread was
          // handed it while it was ours.
          const std::size_t pick = rng() % held.size();
          const std::uint32_t want = marks[pick];
          const std::size_t size = held[pick].get_deleter().bytes / sizeof(std::uint32_t);
          for (std::size_t i = 0; i < size; ++i) corrupted[t] += held[pick][i] != want;
          held.erase(held.begin() + static_cast<std::ptrdiff_t>(pick));
          marks.erase(marks.begin() + static_cast<std::ptrdiff_t>(pick));
        }
      }
    });
  }
  for (auto& th : threads) th.join();
  for (int t = 0; t < kThreads; ++t) EXPECT_EQ(corrupted[t], 0) << "thread " << t;
  EXPECT_LE(chunk_memory_stats().cached_bytes, std::uint64_t{64} << 10);
  EXPECT_GT(chunk_memory_stats().reused, reused_before);
}

TEST(ChunkMemory, GridsRefuseArraysOfAnotherSize) {
  Grid<float> g(8);
  std::vector<ChunkArray<float>> wrong;
  wrong.push_back(make_chunk_array<float>(8 * 8 * 7));
  EXPECT_THROW(g.adopt_chunks({Vec3i{0, 0, 0}}, std::move(wrong)), InvalidArgument);
  EXPECT_EQ(g.chunk_count(), 0u);
  std::vector<ChunkArray<float>> right;
  right.push_back(make_chunk_array<float>(8 * 8 * 8));
  for (int i = 0; i < 512; ++i) right[0][i] = static_cast<float>(i);
  g.adopt_chunks({Vec3i{0, 0, 0}}, std::move(right));
  EXPECT_EQ(g.get({3, 2, 1}), static_cast<float>(1 * 64 + 2 * 8 + 3));
}

TEST(ChunkMemory, AFieldComputedIntoReusedMemoryEqualsOneComputedIntoFresh) {
  // Bounds that end inside chunks: the transform fills the voxels of its edge chunks beyond them.
  const Box3i bounds{{0, 0, 0}, {75, 61, 45}};
  Grid<std::uint8_t> world(16, 0, bounds);
  std::mt19937 rng(5);
  for (int i = 0; i < 300; ++i)
    world.set(
        {static_cast<int>(rng() % 75), static_cast<int>(rng() % 61), static_cast<int>(rng() % 45)},
        1);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.nearest_sites = true;
  DistanceField fresh, reused;
  {
    const CacheLimit none(0);
    fresh = compute_distance_field(world, o);
  }
  const CacheLimit some(std::uint64_t{256} << 20);
  // Dirty arrays of the field's and the sites' chunk sizes first, all held at once and then freed,
  // so that the fields below are written over them.
  {
    constexpr std::size_t kVoxels = 16 * 16 * 16;
    std::vector<ChunkArray<float>> values;
    std::vector<ChunkArray<SiteOffset>> offsets;
    for (int i = 0; i < 64; ++i) {
      values.push_back(make_chunk_array<float>(kVoxels));
      std::memset(values.back().get(), 0x5b, kVoxels * sizeof(float));
      offsets.push_back(make_chunk_array<SiteOffset>(kVoxels));
      std::memset(static_cast<void*>(offsets.back().get()), 0x3c, kVoxels * sizeof(SiteOffset));
    }
  }
  compute_distance_field(world, o);  // its freed chunks are cached
  const std::uint64_t reused_before = chunk_memory_stats().reused;
  reused = compute_distance_field(world, o);
  EXPECT_GT(chunk_memory_stats().reused, reused_before);
  for (int z = 0; z < 48; ++z)
    for (int y = 0; y < 64; ++y)
      for (int x = 0; x < 80; ++x) {
        ASSERT_EQ(reused.distance({x, y, z}), fresh.distance({x, y, z}));
        ASSERT_EQ(reused.sites->get({x, y, z}), fresh.sites->get({x, y, z}));
      }
}
