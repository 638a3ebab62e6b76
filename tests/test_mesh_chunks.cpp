// MeshChunks: after any sequence of edits to the samples, the kept per-chunk meshes weld into
// exactly what meshing the edited volume from scratch gives (array for array with the chunked
// driver, triangle for triangle with mesh_volume's marching cubes), only the chunks an
// edit can reach are re-meshed, per-chunk meshes meet without cracks, and a failed update keeps
// every chunk as it was.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

#include "mesh_compare.h"
#include "voxfield/error.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/primitives.h"

using namespace voxfield;

namespace {

void expect_same(const Mesh& a, const Mesh& b, const std::string& what) {
  ASSERT_EQ(a.vertex_count(), b.vertex_count()) << what;
  ASSERT_EQ(a.indices.size(), b.indices.size()) << what;
  EXPECT_TRUE(a.positions == b.positions) << what;
  EXPECT_TRUE(a.normals == b.normals) << what;
  EXPECT_TRUE(a.indices == b.indices) << what;
}

// The kept chunks after edits against meshing the edited volume from scratch: array for array
// against a new MeshChunks (the same chunked driver), and triangle for triangle against
// mesh_volume(), which numbers its vertices by lattice row (flying_edges.h).
void expect_full_mesh(const MeshChunks& chunks, const ScalarVolume& volume,
                      const MeshOptions& options, const std::string& what) {
  const Mesh kept = chunks.merged();
  expect_same(kept, MeshChunks(volume, options).merged(), what);
  const Mesh full = mesh_volume(volume, options);
  ASSERT_EQ(kept.vertex_count(), full.vertex_count()) << what;
  EXPECT_TRUE(test::corner_triangles(kept) == test::corner_triangles(full)) << what;
}

// A terrain-like field: height above a wavy ground, negative inside.
struct Terrain {
  int n = 48;
  std::vector<float> values;
  ScalarVolume volume;
  Terrain() {
    values.resize(static_cast<std::size_t>(n) * n * n);
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          values[index(x, y, z)] =
              static_cast<float>(z - (20 + 4 * std::sin(x * 0.3) + 3 * std::cos(y * 0.25)));
    volume.size = Vec3i::splat(n);
    volume.values = values.data();
  }
  std::size_t index(int x, int y, int z) const {
    return static_cast<std::size_t>(x + n * (y + n * z));
  }
  // Carves (or adds) a sphere: the field's minimum (union) or maximum with the negated sphere.
  Box3i sphere(Vec3d c, double r, bool add) {
    const Box3i box = Box3i{
        {static_cast<int>(std::floor(c.x - r)) - 1, static_cast<int>(std::floor(c.y - r)) - 1,
         static_cast<int>(std::floor(c.z - r)) - 1},
        {static_cast<int>(std::ceil(c.x + r)) + 2, static_cast<int>(std::ceil(c.y + r)) + 2,
         static_cast<int>(std::ceil(c.z + r)) +
             2}}.intersect(Box3i::from_size(volume.size));
    for (int z = box.begin.z; z < box.end.z; ++z)
      for (int y = box.begin.y; y < box.end.y; ++y)
        for (int x = box.begin.x; x < box.end.x; ++x) {
          const float d =
              static_cast<float>(sdf::sphere(Vec3d{double(x), double(y), double(z)} - c, r));
          float& v = values[index(x, y, z)];
          v = add ? std::min(v, d) : std::max(v, -d);
        }
    return box;
  }
};

}  // namespace

TEST(MeshChunks, EditsReMeshOnlyReachedChunksAndEqualAFullMesh) {
  for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
    SCOPED_TRACE(mesher_name(m));
    Terrain t;
    MeshOptions o;
    o.algorithm = m;
    o.chunk_edge = 8;
    MeshChunks chunks(t.volume, o);
    expect_full_mesh(chunks, t.volume, o, "before any edit");
    std::mt19937 rng(21);
    std::uniform_real_distribution<double> u(4, 44), h(14, 28), r(1.5, 5);
    const Vec3i count = chunks.chunk_count();
    for (int edit = 0; edit < 12; ++edit) {
      const Box3i changed = t.sphere({u(rng), u(rng), h(rng)}, r(rng), edit % 3 != 0);
      const std::vector<Vec3i> remeshed = chunks.update(t.volume, changed);
      EXPECT_LT(remeshed.size(), static_cast<std::size_t>(count.x * count.y * count.z) / 4)
          << "edit " << edit;
      for (const Vec3i& c : remeshed)  // each within reach of the change: 3 samples before, 2 after
        for (int a = 0; a < 3; ++a) {
          EXPECT_LT(c[a] * o.chunk_edge - 3, changed.end[a]);
          EXPECT_GT(std::min((c[a] + 1) * o.chunk_edge, t.n - 1) + 3, changed.begin[a]);
        }
      expect_full_mesh(chunks, t.volume, o, "after edit " + std::to_string(edit));
    }
  }
}

// The reach, pinned: flipping one surface sample at every offset around a chunk border (from
// four before it to four after) and updating just that sample gives the full mesh each time, for
// every mesher — a reach one sample short would leave a chunk stale.
TEST(MeshChunks, OneSampleChangesAtEveryOffsetFromABorder) {
  for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
    SCOPED_TRACE(mesher_name(m));
    Terrain t;
    MeshOptions o;
    o.algorithm = m;
    o.chunk_edge = 8;
    MeshChunks chunks(t.volume, o);
    for (int x = 16 - 4; x <= 16 + 4; ++x) {
      const int y = 20;
      int z = 0;
      while (z + 1 < t.n && t.values[t.index(x, y, z + 1)] < 0) ++z;  // the last inside sample
      float& v = t.values[t.index(x, y, z)];
      v = -v + 0.25f;  // now outside: the surface moves
      chunks.update(t.volume, Box3i{{x, y, z}, {x + 1, y + 1, z + 1}});
      expect_full_mesh(chunks, t.volume, o, "after flipping x = " + std::to_string(x));
    }
  }
}

// Per-chunk meshes drawn on their own: every border vertex of one chunk's mesh is, bit for bit, a
// vertex of a neighbour's mesh, and together they hold the whole mesh's triangles.
TEST(MeshChunks, ChunkMeshesMeetWithoutCracks) {
  Terrain t;
  MeshOptions o;
  o.chunk_edge = 16;
  MeshChunks chunks(t.volume, o);
  const Vec3i count = chunks.chunk_count();
  std::set<std::array<float, 3>> all;
  std::size_t triangles = 0;
  std::vector<Mesh> meshes;
  for (int z = 0; z < count.z; ++z)
    for (int y = 0; y < count.y; ++y)
      for (int x = 0; x < count.x; ++x) meshes.push_back(chunks.chunk_mesh({x, y, z}));
  for (const Mesh& m : meshes) {
    triangles += m.triangle_count();
    all.insert(m.positions.begin(), m.positions.end());
  }
  const Mesh whole = chunks.merged();
  EXPECT_EQ(triangles, whole.triangle_count());
  const std::set<std::array<float, 3>> welded(whole.positions.begin(), whole.positions.end());
  EXPECT_TRUE(all == welded) << all.size() << " distinct chunk vertices, " << welded.size()
                             << " welded";
  EXPECT_THROW(chunks.chunk_mesh(count), InvalidArgument);
}

TEST(MeshChunks, AFailedUpdateKeepsEveryChunk) {
  Terrain t;
  MeshOptions o;
  o.chunk_edge = 8;
  MeshChunks chunks(t.volume, o);
  const Mesh before = chunks.merged();
  const float kept = t.values[t.index(10, 10, 20)];
  t.sphere({30, 30, 20}, 4, true);  // a real change far away...
  t.values[t.index(10, 10, 20)] = std::numeric_limits<float>::quiet_NaN();  // ...and a NaN
  EXPECT_THROW(chunks.update(t.volume, Box3i{{8, 8, 14}, {34, 34, 26}}), InvalidArgument);
  expect_same(chunks.merged(), before, "after the failed update");
  t.values[t.index(10, 10, 20)] = kept;
  ScalarVolume moved = t.volume;
  moved.spacing_units = {2, 2, 2};
  EXPECT_THROW(chunks.update(moved, Box3i{{0, 0, 0}, {4, 4, 4}}), InvalidArgument);
  EXPECT_TRUE(chunks.update(t.volume, Box3i{{100, 100, 100}, {104, 104, 104}})
                  .empty());  // outside: nothing
}
