// The meshers' parallel paths under ThreadSanitizer (the tsan preset runs this executable): chunks
// meshed concurrently, the weld writing disjoint ranges of the output from several threads,
// a whole volume's rows counted and written concurrently (Flying Edges' passes), and MeshChunks
// re-meshing dirty chunks in parallel — the same mesh as on one thread.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "mesh_compare.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/parallel.h"

using namespace voxfield;

TEST(ParallelMesh, ThreadsGiveTheSameMesh) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  const int n = 33;
  std::vector<float> v(static_cast<std::size_t>(n) * n * n);
  for (float& x : v) x = u(rng);
  const ScalarVolume vol{Vec3i::splat(n), v.data()};
  for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
    MeshOptions o;
    o.algorithm = m;
    o.chunk_edge = 4;
    Mesh one;
    {
      ThreadLimit limit(1);
      one = mesh_volume(vol, o);
    }
    const Mesh many = mesh_volume(vol, o);
    EXPECT_TRUE(one.positions == many.positions && one.indices == many.indices) << mesher_name(m);
    MeshChunks chunks(vol, o);
    for (int i = 0; i < 8; ++i) v[static_cast<std::size_t>(i * 977 % v.size())] *= -1;
    chunks.update(vol, Box3i::from_size(vol.size));
    // A full re-mesh by the same chunked driver, array for array; mesh_volume() (Flying Edges'
    // passes, numbered by row) triangle for triangle.
    const Mesh kept = chunks.merged();
    EXPECT_TRUE(kept.indices == MeshChunks(vol, o).merged().indices) << mesher_name(m);
    EXPECT_TRUE(test::corner_triangles(kept) == test::corner_triangles(mesh_volume(vol, o)))
        << mesher_name(m);
  }
}
