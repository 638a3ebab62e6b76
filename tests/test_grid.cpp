// Grid<T> against a plain dense array: every chunk edge, odd sizes, negative coordinates, boxes
// not aligned to chunks, uniform-chunk collapse, bounds.
#include <gtest/gtest.h>

#include <atomic>
#include <random>

#include "voxfield/grid.h"

using namespace voxfield;

namespace {

// The oracle: a dense array over a box.
template <class T>
struct Dense {
  Box3i box;
  std::vector<T> v;
  Dense(Box3i b, T fill) : box(b), v(static_cast<std::size_t>(b.volume()), fill) {}
  T& at(Vec3i p) {
    const Vec3i s = box.size();
    const Vec3i q = p - box.begin;
    return v[(static_cast<std::size_t>(q.z) * s.y + q.y) * s.x + q.x];
  }
};

Vec3i random_point(std::mt19937& rng, const Box3i& b) {
  auto r = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi - 1)(rng); };
  return {r(b.begin.x, b.end.x), r(b.begin.y, b.end.y), r(b.begin.z, b.end.z)};
}

Box3i random_box(std::mt19937& rng, const Box3i& within) {
  const Vec3i a = random_point(rng, within), b = random_point(rng, within);
  return Box3i::from_inclusive({std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)},
                               {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)});
}

class GridEdges : public ::testing::TestWithParam<int> {};

}  // namespace

TEST_P(GridEdges, RandomEditsMatchDenseOracle) {
  const int edge = GetParam();
  std::mt19937 rng(1234 + edge);
  // Odd size straddling the origin so negative chunk coordinates are exercised.
  const Box3i world{{-37, -5, -150}, {61, 3 * edge + 7, -150 + 2 * edge + 3}};
  Grid<std::uint16_t> g(edge, 7);
  Dense<std::uint16_t> d(world, 7);
  for (int step = 0; step < 60; ++step) {
    const int kind = step % 3;
    if (kind == 0) {
      for (int i = 0; i < 200; ++i) {
        const Vec3i p = random_point(rng, world);
        const std::uint16_t v = static_cast<std::uint16_t>(rng() % 4 + 6);
        g.set(p, v);
        d.at(p) = v;
      }
    } else if (kind == 1) {
      const Box3i b = random_box(rng, world);
      const std::uint16_t v = static_cast<std::uint16_t>(rng() % 3 + 6);
      g.fill(b, v);
      for (int z = b.begin.z; z < b.end.z; ++z)
        for (int y = b.begin.y; y < b.end.y; ++y)
          for (int x = b.begin.x; x < b.end.x; ++x) d.at({x, y, z}) = v;
    } else {
      const Box3i b = random_box(rng, world);
      std::vector<std::uint16_t> in(static_cast<std::size_t>(b.volume()));
      for (auto& x : in) x = static_cast<std::uint16_t>(rng() % 2 ? 7 : rng() % 100);
      g.copy_from_dense(b, in.data());
      std::size_t i = 0;
      for (int z = b.begin.z; z < b.end.z; ++z)
        for (int y = b.begin.y; y < b.end.y; ++y)
          for (int x = b.begin.x; x < b.end.x; ++x) d.at({x, y, z}) = in[i++];
    }
  }
  // Whole-world copy and per-voxel reads agree with the oracle.
  std::vector<std::uint16_t> out(static_cast<std::size_t>(world.volume()));
  g.copy_to_dense(world, out.data());
  EXPECT_EQ(out, d.v);
  Grid<std::uint16_t>::ReadAccessor acc(g);
  std::int64_t non_bg = 0;
  Vec3i lo = world.end, hi = world.begin;
  for (int z = world.begin.z; z < world.end.z; ++z)
    for (int y = world.begin.y; y < world.end.y; ++y)
      for (int x = world.begin.x; x < world.end.x; ++x) {
        const std::uint16_t expect = d.at({x, y, z});
        ASSERT_EQ(g.get({x, y, z}), expect);
        ASSERT_EQ(acc.get({x, y, z}), expect);
        if (expect != 7) {
          ++non_bg;
          lo = {std::min(lo.x, x), std::min(lo.y, y), std::min(lo.z, z)};
          hi = {std::max(hi.x, x), std::max(hi.y, y), std::max(hi.z, z)};
        }
      }
  EXPECT_EQ(g.count_non_background(), non_bg);
  EXPECT_EQ(g.content_bounds(), Box3i::from_inclusive(lo, hi));
  // An unaligned sub-box copy, partly outside anything stored.
  const Box3i sub{{-40, 1, -151}, {5, edge + 2, -140}};
  std::vector<std::uint16_t> part(static_cast<std::size_t>(sub.volume()));
  g.copy_to_dense(sub, part.data());
  std::size_t i = 0;
  for (int z = sub.begin.z; z < sub.end.z; ++z)
    for (int y = sub.begin.y; y < sub.end.y; ++y)
      for (int x = sub.begin.x; x < sub.end.x; ++x, ++i) {
        const std::uint16_t expect = world.contains(Vec3i{x, y, z}) ? d.at({x, y, z}) : 7;
        ASSERT_EQ(part[i], expect) << x << "," << y << "," << z;
      }
  // A copy is deep and equal.
  Grid<std::uint16_t> copy = g;
  g.fill(world, 9);
  std::vector<std::uint16_t> out2(out.size());
  copy.copy_to_dense(world, out2.data());
  EXPECT_EQ(out2, d.v);
}

TEST_P(GridEdges, UniformChunksCollapse) {
  const int edge = GetParam();
  Grid<std::uint8_t> g(edge);
  const Box3i chunk0 = g.chunk_box({0, 0, 0});
  // Filling a whole chunk stores one value, no voxel array.
  g.fill(chunk0, 3);
  EXPECT_EQ(g.memory().uniform_chunks, 1u);
  EXPECT_EQ(g.memory().dense_chunks, 0u);
  EXPECT_EQ(g.get({edge - 1, 0, edge - 1}), 3);
  // Changing one voxel makes it dense; restoring it collapses it again (O(1) path).
  g.set({1, 2, 3}, 5);
  EXPECT_EQ(g.memory().dense_chunks, 1u);
  g.set({1, 2, 3}, 3);
  EXPECT_EQ(g.memory().dense_chunks, 0u);
  EXPECT_EQ(g.memory().uniform_chunks, 1u);
  // Carving the whole chunk voxel by voxel back to the background removes it entirely.
  Grid<std::uint8_t> h(edge);
  h.set({-1, -1, -1}, 1);
  h.set({-2, -1, -1}, 1);
  EXPECT_EQ(h.chunk_count(), 1u);
  h.set({-1, -1, -1}, 0);
  EXPECT_EQ(h.chunk_count(), 1u);
  h.set({-2, -1, -1}, 0);
  EXPECT_EQ(h.chunk_count(), 0u);
  // A partly filled chunk that a second fill completes collapses too.
  Grid<std::uint8_t> k(edge);
  k.fill({{0, 0, 0}, {edge, edge, edge / 2}}, 4);
  EXPECT_EQ(k.memory().dense_chunks, 1u);
  k.fill({{0, 0, edge / 2}, {edge, edge, edge}}, 4);
  EXPECT_EQ(k.memory().dense_chunks, 0u);
  EXPECT_EQ(k.memory().uniform_chunks, 1u);
  // Eight fills of a chunk's octants (a .vdb's small tiles): dense until the last one lands, then
  // one value; filled back with the background octant by octant, the chunk goes.
  for (const std::uint8_t value : {std::uint8_t{6}, std::uint8_t{0}}) {
    const int h = edge / 2;
    for (int i = 0; i < 8; ++i) {
      const Vec3i o{(i & 1) * h, ((i >> 1) & 1) * h, (i >> 2) * h};
      k.fill({o, o + Vec3i::splat(h)}, value);
      EXPECT_EQ(k.memory().dense_chunks, i < 7 ? 1u : 0u) << int(value) << " octant " << i;
    }
    EXPECT_EQ(k.chunk_count(), value == 0 ? 0u : 1u);
    EXPECT_EQ(k.get({edge - 1, 0, 1}), value);
  }
  // Uniform by per-voxel writes of a new value: compact() collapses it.
  Grid<std::uint8_t> m(edge);
  for (int z = 0; z < edge; ++z)
    for (int y = 0; y < edge; ++y)
      for (int x = 0; x < edge; ++x) m.set({x, y, z}, 2);
  m.compact();
  EXPECT_EQ(m.memory().dense_chunks, 0u);
  EXPECT_EQ(m.memory().uniform_chunks, 1u);
  EXPECT_EQ(m.count_non_background(), std::int64_t{edge} * edge * edge);
}

TEST_P(GridEdges, MemoryAccounting) {
  const int edge = GetParam();
  Grid<std::uint8_t> g(edge);
  // 8 dense chunks: about one byte per voxel.
  for (int c = 0; c < 8; ++c) g.set({c * edge, 0, 0}, 1);
  GridMemory m = g.memory();
  EXPECT_EQ(m.dense_chunks, 8u);
  EXPECT_GE(m.bytes_per_voxel(), 1.0);
  EXPECT_LT(m.bytes_per_voxel(), 1.0 + 2048.0 / (edge * edge * edge) + 0.05);
  // Uniform chunks cost almost nothing per voxel.
  Grid<std::uint8_t> u(edge);
  u.fill({{0, 0, 0}, {8 * edge, edge, edge}}, 1);
  m = u.memory();
  EXPECT_EQ(m.uniform_chunks, 8u);
  EXPECT_LT(m.bytes_per_voxel(), 0.2);
}

TEST_P(GridEdges, GenerateChunksAndParallelIteration) {
  const int edge = GetParam();
  Grid<float> g(edge, 1.5f);
  std::vector<Vec3i> coords{{0, 0, 0}, {-1, 2, 0}, {3, -4, 1}};
  g.generate_chunks(coords, [&](Vec3i c, float* v) {
    const std::int64_t n = std::int64_t{edge} * edge * edge;
    for (std::int64_t i = 0; i < n; ++i)
      v[i] = c.x == 3 ? 2.0f : (c.x == 0 ? 1.5f : static_cast<float>(i % 7));
  });
  // Chunk (0,0,0) came out uniform background: not stored. (3,-4,1) uniform 2: one value.
  EXPECT_EQ(g.chunk_count(), 2u);
  const GridMemory m = g.memory();
  EXPECT_EQ(m.dense_chunks, 1u);
  EXPECT_EQ(m.uniform_chunks, 1u);
  EXPECT_EQ(g.get(g.chunk_box({3, -4, 1}).begin), 2.0f);
  EXPECT_EQ(g.get(g.chunk_box({-1, 2, 0}).begin + Vec3i{3, 0, 0}), 3.0f);
  std::atomic<int> visited{0};
  std::atomic<std::int64_t> dense_voxels{0};
  g.parallel_for_each_chunk([&](const ChunkView<float>& c) {
    ++visited;
    if (!c.uniform()) dense_voxels += std::int64_t{edge} * edge * edge;
    EXPECT_EQ(c.box, g.chunk_box(c.coord));
  });
  EXPECT_EQ(visited.load(), 2);
  EXPECT_EQ(dense_voxels.load(), std::int64_t{edge} * edge * edge);
  const auto sorted = g.chunk_coords();
  ASSERT_EQ(sorted.size(), 2u);
  EXPECT_EQ(sorted[0], (Vec3i{-1, 2, 0}));
  EXPECT_EQ(sorted[1], (Vec3i{3, -4, 1}));
}

INSTANTIATE_TEST_SUITE_P(AllEdges, GridEdges, ::testing::Values(8, 16, 32, 64, 128));

TEST(Grid, RejectsBadChunkEdges) {
  for (int bad : {0, 4, 7, 12, 33, 256, -32}) {
    EXPECT_THROW(Grid<std::uint8_t>{bad}, InvalidArgument) << bad;
  }
  EXPECT_THROW((Grid<std::uint8_t>{32, 0, Box3i{{0, 0, 0}, {0, 5, 5}}}), InvalidArgument);
}

TEST(Grid, BoundedGridRejectsWritesOutsideAndChangesNothing) {
  const Box3i bounds{{0, 0, 0}, {40, 40, 40}};
  Grid<std::uint8_t> g(16, 0, bounds);
  g.set({39, 39, 39}, 1);
  EXPECT_THROW(g.set({40, 0, 0}, 1), InvalidArgument);
  EXPECT_THROW(g.set({-1, 0, 0}, 1), InvalidArgument);
  EXPECT_THROW(g.fill({{30, 30, 30}, {41, 35, 35}}, 2), InvalidArgument);
  std::vector<std::uint8_t> in(8, 3);
  EXPECT_THROW(g.copy_from_dense({{39, 39, 39}, {41, 41, 41}}, in.data()), InvalidArgument);
  EXPECT_EQ(g.count_non_background(), 1);
  EXPECT_EQ(g.get({35, 35, 35}), 0);
  EXPECT_EQ(g.get({100, 0, 0}), 0);  // reads outside are the background
  // Chunks that straddle the bounds only keep voxels inside.
  g.generate_chunks({{2, 2, 2}}, [](Vec3i, std::uint8_t* v) { std::fill(v, v + 16 * 16 * 16, 9); });
  EXPECT_EQ(g.get({39, 39, 39}), 9);
  EXPECT_EQ(g.get({40, 39, 39}), 0);
  EXPECT_EQ(g.count_non_background(), 8 * 8 * 8);
  EXPECT_THROW(g.generate_chunks({{3, 0, 0}}, [](Vec3i, std::uint8_t*) {}), InvalidArgument);
}

// The corners of the supported coordinate range (box.h) are stored and read back; one step beyond
// is refused, and reads beyond it (any int32) return the background without overflowing.
TEST(Grid, ExtremeCoordinates) {
  Grid<std::uint8_t> g(128);
  const Vec3i far_lo = Vec3i::splat(-kCoordLimit);
  const Vec3i far_hi = Vec3i::splat(kCoordLimit - 1);
  g.set(far_lo, 1);
  g.set(far_hi, 2);
  EXPECT_EQ(g.get(far_lo), 1);
  EXPECT_EQ(g.get(far_hi), 2);
  EXPECT_EQ(g.count_non_background(), 2);
  EXPECT_EQ(g.content_bounds(), (Box3i{far_lo, Vec3i::splat(kCoordLimit)}));
  EXPECT_THROW(g.set(Vec3i::splat(INT32_MIN), 3), InvalidArgument);
  EXPECT_THROW(g.set(Vec3i::splat(kCoordLimit), 3), InvalidArgument);
  EXPECT_EQ(g.get(Vec3i::splat(INT32_MIN)), 0);
  EXPECT_EQ(g.get(Vec3i::splat(INT32_MAX)), 0);
  EXPECT_EQ(g.count_non_background(), 2);
}
