// mesh_stats' edge census against a brute-force census (a std::map from each undirected edge to its
// uses and their directions) on random triangle soups that hold every kind of edge: boundary,
// manifold, misoriented, non-manifold, and the edges of degenerate triangles. Area and volume
// against a closed box whose values are known exactly.
#include <gtest/gtest.h>

#include <cstdint>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/mesh.h"

using namespace voxfield;

namespace {

struct Census {
  std::size_t edges = 0, boundary = 0, nonmanifold = 0, misoriented = 0, degenerate = 0;
};

Census brute_force_census(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<int, int>> uses;  // (count, forward)
  Census c;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    const std::uint32_t* v = m.indices.data() + 3 * t;
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) ++c.degenerate;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = v[k], b = v[(k + 1) % 3];
      auto& u = uses[{std::min(a, b), std::max(a, b)}];
      ++u.first;
      u.second += a < b ? 1 : 0;
    }
  }
  for (const auto& [edge, u] : uses) {
    ++c.edges;
    if (u.first == 1)
      ++c.boundary;
    else if (u.first > 2)
      ++c.nonmanifold;
    else if (u.second != 1)
      ++c.misoriented;
  }
  return c;
}

}  // namespace

TEST(MeshStats, TheEdgeCensusEqualsABruteForceCensusOnRandomSoups) {
  std::mt19937 rng(20261204);
  Census seen;  // over all trials: every kind of edge must have been exercised
  for (int trial = 0; trial < 200; ++trial) {
    // Few vertices for many triangles, so that edges are shared once, twice and more often.
    const int vertices = 3 + static_cast<int>(rng() % 40);
    const int triangles = 1 + static_cast<int>(rng() % 120);
    Mesh m;
    for (int i = 0; i < vertices; ++i)
      m.positions.push_back({static_cast<float>(rng() % 17), static_cast<float>(rng() % 13),
                             static_cast<float>(rng() % 11)});
    for (int t = 0; t < 3 * triangles; ++t)
      m.indices.push_back(static_cast<std::uint32_t>(rng() % static_cast<unsigned>(vertices)));
    // Closed pairs: a triangle and its reverse (each edge used twice, in opposite directions), so
    // that manifold edges are common too.
    for (int t = 0; t < triangles / 3; ++t) {
      const std::uint32_t a = rng() % vertices, b = rng() % vertices, c = rng() % vertices;
      m.indices.insert(m.indices.end(), {a, b, c, a, c, b});
    }
    const MeshStats s = mesh_stats(m);
    const Census c = brute_force_census(m);
    EXPECT_EQ(s.vertices, m.positions.size());
    EXPECT_EQ(s.triangles, m.triangle_count());
    EXPECT_EQ(s.edges, c.edges) << "trial " << trial;
    EXPECT_EQ(s.boundary_edges, c.boundary) << "trial " << trial;
    EXPECT_EQ(s.nonmanifold_edges, c.nonmanifold) << "trial " << trial;
    EXPECT_EQ(s.misoriented_edges, c.misoriented) << "trial " << trial;
    EXPECT_EQ(s.degenerate_triangles, c.degenerate) << "trial " << trial;
    seen.boundary += c.boundary;
    seen.nonmanifold += c.nonmanifold;
    seen.misoriented += c.misoriented;
    seen.degenerate += c.degenerate;
    seen.edges += c.edges - c.boundary - c.nonmanifold - c.misoriented;  // manifold, oriented
    EXPECT_EQ(s.euler_characteristic, static_cast<std::int64_t>(s.vertices) -
                                          static_cast<std::int64_t>(c.edges) +
                                          static_cast<std::int64_t>(s.triangles));
  }
  EXPECT_GT(seen.boundary, 0u);
  EXPECT_GT(seen.nonmanifold, 0u);
  EXPECT_GT(seen.misoriented, 0u);
  EXPECT_GT(seen.degenerate, 0u);
  EXPECT_GT(seen.edges, 0u);
}

TEST(MeshStats, AClosedBoxIsWatertightWithItsAreaVolumeAndEulerCharacteristic) {
  // A 2 x 3 x 4 box from (1, 1, 1), 12 triangles facing out, and an unused vertex at the end
  // (vertices count every position, used or not).
  Mesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back(
        {1.0f + 2.0f * (i & 1), 1.0f + 3.0f * ((i >> 1) & 1), 1.0f + 4.0f * ((i >> 2) & 1)});
  m.positions.push_back({9, 9, 9});
  const std::uint32_t faces[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                      {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                      {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  for (const auto& f : faces) m.indices.insert(m.indices.end(), {f[0], f[1], f[2]});
  const MeshStats s = mesh_stats(m);
  EXPECT_TRUE(s.watertight());
  EXPECT_EQ(s.edges, 18u);
  EXPECT_EQ(s.euler_characteristic, 9 - 18 + 12);  // 2 for the box, plus the unused vertex
  EXPECT_DOUBLE_EQ(s.area_units2, 2 * (2 * 3 + 2 * 4 + 3 * 4));
  EXPECT_NEAR(s.signed_volume_units3, 24, 1e-12);
  // One face reversed: its three edges are now traversed twice the same way.
  std::swap(m.indices[1], m.indices[2]);
  const MeshStats flipped = mesh_stats(m);
  EXPECT_FALSE(flipped.watertight());
  EXPECT_EQ(flipped.misoriented_edges, 3u);
}

TEST(MeshStats, AnIndexPastTheLastVertexIsRefusedByName) {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {0, 1, 3};
  EXPECT_THROW(
      {
        try {
          mesh_stats(m);
        } catch (const InvalidArgument& e) {
          EXPECT_NE(std::string(e.what()).find("index 3 is past the last vertex"),
                    std::string::npos);
          throw;
        }
      },
      InvalidArgument);
}
