// Meshes over the ranks of an MPI job (mpi.h's mesh_volume) against one process: every rank builds
// the same random volume but hands the mesher only the sample planes its layers read; rank 0's mesh
// must equal one process's over the whole lattice array for array — mesh_volume's for every mesher
// (slabs of the whole-volume passes), the chunked mesher's with an analytic gradient (pieces) —
// for any number of ranks (more ranks than layers included), and a failure on one rank reaches all.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <random>

#include "../wave_volume.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/mesh_pieces.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/mpi.h"

namespace voxfield {
namespace {

int rank_of(MPI_Comm c) {
  int r = 0;
  MPI_Comm_rank(c, &r);
  return r;
}
int size_of(MPI_Comm c) {
  int n = 0;
  MPI_Comm_size(c, &n);
  return n;
}

// This rank's planes of the whole volume, copied (the mesher sees nothing else).
std::vector<float> my_planes(const mpi::MeshLayers& layers, const std::vector<float>& whole,
                             Vec3i n, int rank) {
  const auto [z0, z1] = layers.planes(rank);
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  return {whole.begin() + static_cast<std::ptrdiff_t>(plane * z0),
          whole.begin() + static_cast<std::ptrdiff_t>(plane * z1)};
}

// What one process makes of the whole lattice, as mpi::mesh_volume promises it: mesh_volume's
// arrays by slabs; the chunked driver's with an analytic gradient (pieces).
Mesh one_process(const ScalarVolume& vol, const MeshOptions& o) {
  return mesh_slab_applies(o) ? mesh_volume(vol, o) : MeshChunks(vol, o).merged();
}

// An analytic gradient (any function of the position will do): the options take the pieces path.
std::array<double, 3> towards_centre(const std::array<double, 3>& p) {
  return {p[0] - 5.0, p[1] - 10.0, 0.3 * (p[2] - 14.0)};
}

TEST(MpiMesh, EqualsOneProcessOnAnyNumberOfRanks) {
  MPI_Comm comm = MPI_COMM_WORLD;
  const int rank = rank_of(comm), ranks = size_of(comm);
  const Vec3i n{19, 23, 37};
  const std::vector<float> whole = test::wave_volume(n, 3, 3, 0.6, false);
  ScalarVolume frame{n, nullptr};
  frame.spacing_units = {0.5, 1.0, 0.8};
  frame.origin_units = {1.5, -2.0, 0.25};
  for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring})
    for (int edge : {5, 12, 36})  // 36: one layer, so only the last rank has any
      for (bool analytic : {false, true}) {
        if (analytic && edge == 36) continue;
        SCOPED_TRACE(std::string(mesher_name(m)) + " chunk edge " + std::to_string(edge) +
                     (analytic ? " analytic gradient" : ""));
        MeshOptions o;
        o.algorithm = m;
        o.chunk_edge = edge;
        if (analytic) o.gradient = towards_centre;
        const mpi::MeshLayers layers = mpi::partition_mesh_layers(n, edge, ranks);
        EXPECT_EQ(layers.layers.front(), 0);
        EXPECT_EQ(layers.layers.back(), mesh_chunk_layers(n, edge));
        const std::vector<float> planes = my_planes(layers, whole, n, rank);
        mpi::ExchangeStats stats;
        const Mesh got = mpi::mesh_volume(comm, layers, frame, planes.data(), o, &stats);
        if (rank != 0) {
          EXPECT_EQ(got.triangle_count(), 0u);
          continue;
        }
        ScalarVolume vol = frame;
        vol.values = whole.data();
        const Mesh want = one_process(vol, o);
        ASSERT_GT(want.triangle_count(), 100u);
        ASSERT_EQ(got.positions.size(), want.positions.size());
        EXPECT_TRUE(got.positions == want.positions);
        EXPECT_TRUE(got.normals == want.normals);
        EXPECT_TRUE(got.indices == want.indices);
        if (ranks > 1 && !layers.empty(1)) {
          EXPECT_GT(stats.bytes_received, 0u);
        }
      }
}

// Layers dealt by weight: cuts where the running weight is nearest each rank's share, empty runs
// where one layer outweighs several shares; bad weights refused.
TEST(MpiMesh, LayersAreDealtByWeight) {
  const Vec3i n{5, 5, 41};  // 40 cells: 10 layers of 4
  const std::vector<double> w{0, 0, 0, 100, 100, 0, 0, 0, 0, 0};
  EXPECT_EQ(mpi::partition_mesh_layers(n, 4, 2, w).layers, (std::vector<std::int32_t>{0, 4, 10}));
  EXPECT_EQ(mpi::partition_mesh_layers(n, 4, 4, w).layers,
            (std::vector<std::int32_t>{0, 3, 4, 4, 10}));
  const std::vector<double> even(10, 1.0);
  EXPECT_EQ(mpi::partition_mesh_layers(n, 4, 2, even).layers,
            mpi::partition_mesh_layers(n, 4, 2).layers);
  EXPECT_THROW(mpi::partition_mesh_layers(n, 4, 2, std::vector<double>(9, 1.0)), InvalidArgument);
  std::vector<double> bad = even;
  bad[3] = -1;
  EXPECT_THROW(mpi::partition_mesh_layers(n, 4, 2, bad), InvalidArgument);
  bad[3] = std::nan("");
  EXPECT_THROW(mpi::partition_mesh_layers(n, 4, 2, bad), InvalidArgument);
}

// A terrain-like volume whose surface lies in a few planes: the layers' weights, counted from equal
// shares of the planes, deal the surface's layers out among the ranks, and the mesh is the same.
TEST(MpiMesh, ContentBalancedLayersGiveTheSameMesh) {
  MPI_Comm comm = MPI_COMM_WORLD;
  const int rank = rank_of(comm), ranks = size_of(comm);
  const Vec3i n{24, 20, 60};
  std::vector<float> whole(static_cast<std::size_t>(n.x) * n.y * n.z);
  std::size_t i = 0;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x, ++i)  // ground at z near 40: below is inside
        whole[i] = static_cast<float>(z - 40 - 3 * std::sin(0.5 * x) * std::cos(0.4 * y));
  MeshOptions o;
  o.chunk_edge = 4;
  const int z0 = n.z * rank / ranks, z1 = n.z * (rank + 1) / ranks;
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  const std::vector<double> weights =
      mpi::mesh_layer_weights(comm, n, z0, z1, whole.data() + plane * z0, o);
  ASSERT_EQ(weights.size(), 15u);
  // Layers 9..10 (planes 36..44) hold the surface; the others only their samples' 64th.
  EXPECT_GT(weights[9], 3 * weights[2]);
  EXPECT_EQ(weights[2], weights[3]);
  const mpi::MeshLayers layers = mpi::partition_mesh_layers(n, 4, ranks, weights);
  // Rank 0 gets the empty layers below the ground: more than its count's share.
  if (ranks > 1) {
    EXPECT_GT(layers.layers[1], mpi::partition_mesh_layers(n, 4, ranks).layers[1]);
  }
  const std::vector<float> planes = my_planes(layers, whole, n, rank);
  const Mesh got = mpi::mesh_volume(comm, layers, ScalarVolume{n, nullptr}, planes.data(), o);
  if (rank == 0) {
    const Mesh want = one_process(ScalarVolume{n, whole.data()}, o);
    ASSERT_GT(want.triangle_count(), 100u);
    EXPECT_TRUE(got.positions == want.positions);
    EXPECT_TRUE(got.indices == want.indices);
  }
  // Planes passed by no rank or by two: refused on every rank.
  EXPECT_THROW((void)mpi::mesh_layer_weights(comm, n, 0, rank == 0 ? n.z - 1 : 0, whole.data(), o),
               mpi::RankError);
  if (ranks > 1) {
    EXPECT_THROW((void)mpi::mesh_layer_weights(comm, n, 0, n.z, whole.data(), o), mpi::RankError);
  }
}

TEST(MpiMesh, AFailureOnOneRankReachesEveryRank) {
  MPI_Comm comm = MPI_COMM_WORLD;
  const int rank = rank_of(comm), ranks = size_of(comm);
  const Vec3i n{9, 9, 8 * ranks + 1};
  std::vector<float> whole = test::wave_volume(n, 4, 3, 0.6, false);
  // A NaN in the last rank's own cells.
  whole[whole.size() - 9 * 9 * 3 + 40] = std::nanf("");
  MeshOptions o;
  o.chunk_edge = 8;
  const mpi::MeshLayers layers = mpi::partition_mesh_layers(n, 8, ranks);
  const std::vector<float> planes = my_planes(layers, whole, n, rank);
  try {
    (void)mpi::mesh_volume(comm, layers, ScalarVolume{n, nullptr}, planes.data(), o);
    ADD_FAILURE() << "no rank failed";
  } catch (const mpi::RankError& e) {
    EXPECT_EQ(e.rank(), ranks - 1) << e.what();
    EXPECT_NE(e.message().find("is NaN"), std::string::npos) << e.what();
  }
  // Layers cut for another number of ranks, or another chunk edge: refused on every rank.
  const mpi::MeshLayers wrong = mpi::partition_mesh_layers(n, 8, ranks + 1);
  EXPECT_THROW((void)mpi::mesh_volume(comm, wrong, ScalarVolume{n, nullptr}, planes.data(), o),
               mpi::RankError);
  o.chunk_edge = 4;
  EXPECT_THROW((void)mpi::mesh_volume(comm, layers, ScalarVolume{n, nullptr}, planes.data(), o),
               mpi::RankError);
}

}  // namespace
}  // namespace voxfield
