// One mesh file written by every rank, each its own share (mpi.h's write_mesh_volume), against one
// process: the file must be byte for byte what encode_mesh writes for one process's mesh of the
// whole lattice (mesh_volume's by slabs, the chunked mesher's with an analytic gradient: orphans
// included), in every format, for every mesher, any number of ranks, ranks
// without layers anywhere in the order; the census must equal mesh_stats of that mesh; and a
// failure on any rank leaves the target as it was.
#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "../wave_volume.h"
#include "mpi_ranks.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_pieces.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/mpi.h"
#include "voxfield/world_io.h"

namespace voxfield {
namespace {

using test::comm;
using test::rank;
using test::ranks;

// A directory every rank shares (named by rank 0's process), removed at the end.
class SharedDir {
 public:
  SharedDir() {
    long id = static_cast<long>(getpid());
    MPI_Bcast(&id, 1, MPI_LONG, 0, comm());
    path_ = std::filesystem::temp_directory_path() / ("voxfield_mpi_mesh_" + std::to_string(id));
    if (rank() == 0) std::filesystem::create_directories(path_);
    MPI_Barrier(comm());
  }
  ~SharedDir() {
    MPI_Barrier(comm());
    if (rank() == 0) std::filesystem::remove_all(path_);
  }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<float> my_planes(const mpi::MeshLayers& layers, const std::vector<float>& whole,
                             Vec3i n) {
  const auto [z0, z1] = layers.planes(rank());
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  return {whole.begin() + static_cast<std::ptrdiff_t>(plane * z0),
          whole.begin() + static_cast<std::ptrdiff_t>(plane * z1)};
}

// The written file's summary and census against one process's mesh `want`, and (rank 0) its
// bytes against encode_mesh(want).
void expect_summary_and_file(const mpi::MeshFileSummary& got, const Mesh& want,
                             const std::filesystem::path& path) {
  EXPECT_EQ(got.vertices, want.vertex_count());
  EXPECT_EQ(got.triangles, want.triangle_count());
  ASSERT_TRUE(got.census.has_value());
  const MeshStats w = mesh_stats(want);
  EXPECT_EQ(got.census->edges, w.edges);
  EXPECT_EQ(got.census->boundary_edges, w.boundary_edges);
  EXPECT_EQ(got.census->nonmanifold_edges, w.nonmanifold_edges);
  EXPECT_EQ(got.census->misoriented_edges, w.misoriented_edges);
  EXPECT_EQ(got.census->degenerate_triangles, w.degenerate_triangles);
  EXPECT_EQ(got.census->euler_characteristic, w.euler_characteristic);
  EXPECT_NEAR(got.census->area_units2, w.area_units2, 1e-9 * w.area_units2);
  EXPECT_NEAR(got.census->signed_volume_units3, w.signed_volume_units3,
              1e-9 * std::abs(w.signed_volume_units3) + 1e-9);
  if (rank() == 0) {
    const std::vector<std::uint8_t> bytes = read_bytes(path);
    const std::vector<std::uint8_t> expected = encode_mesh(want, mesh_format_of(path));
    ASSERT_EQ(bytes.size(), expected.size());
    EXPECT_TRUE(bytes == expected);
  }
}

// Writes the mesh over the ranks and checks the file and the census on rank 0.
void expect_file_of_whole(const mpi::MeshLayers& layers, const std::vector<float>& whole,
                          const ScalarVolume& frame, const MeshOptions& o,
                          const std::filesystem::path& path) {
  const std::vector<float> planes = my_planes(layers, whole, frame.size);
  const mpi::MeshFileSummary got = mpi::write_mesh_volume(
      comm(), layers, frame, planes.empty() ? nullptr : planes.data(), o, path, true);
  ScalarVolume vol = frame;
  vol.values = whole.data();
  const Mesh want = mesh_slab_applies(o) ? mesh_volume(vol, o) : MeshChunks(vol, o).merged();
  ASSERT_GT(want.triangle_count(), 100u);
  expect_summary_and_file(got, want, path);
}

TEST(MpiMeshFile, IsTheFileOneProcessWritesInEveryFormat) {
  const SharedDir dir;
  const Vec3i n{19, 23, 37};
  const std::vector<float> whole = test::wave_volume(n, 3, 3, 0.6, false);
  ScalarVolume frame{n, nullptr};
  frame.spacing_units = {0.5, 1.0, 0.8};
  frame.origin_units = {1.5, -2.0, 0.25};
  for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring})
    for (int edge : {4, 12, 36})  // 36: one layer, so only the last rank has any
      for (const char* ext : {".ply", ".obj", ".stl", ".glb"}) {
        if (edge != 4 && std::string(ext) != ".glb") continue;  // every format once per mesher
        SCOPED_TRACE(std::string(mesher_name(m)) + " chunk edge " + std::to_string(edge) + " " +
                     ext);
        MeshOptions o;
        o.algorithm = m;
        o.chunk_edge = edge;
        const mpi::MeshLayers layers = mpi::partition_mesh_layers(n, edge, ranks());
        expect_file_of_whole(layers, whole, frame, o, dir / (std::string("mesh") + ext));
      }
}

// Runs without layers before, between and after others (a content-balanced cut gives them): such
// a rank has no neighbours, and the ranks beside it weld with each other.
TEST(MpiMeshFile, RanksWithoutLayersAnywhere) {
  const SharedDir dir;
  const Vec3i n{17, 15, 41};  // 40 cells: 10 layers of 4
  const std::vector<float> whole = test::wave_volume(n, 4, 2, 0.5, false);
  // Marching cubes and surface nets by slabs, and surface nets with an analytic gradient (by
  // pieces: PieceWeld's neighbours).
  for (int k = 0; k < 3; ++k) {
    const Mesher m = k == 0 ? Mesher::kMarchingCubes : Mesher::kSurfaceNets;
    MeshOptions o;
    o.algorithm = m;
    o.chunk_edge = 4;
    if (k == 2)
      o.gradient = [](const std::array<double, 3>& p) {
        return std::array<double, 3>{p[0] - 8.0, p[1] - 7.0, 0.5 * (p[2] - 20.0)};
      };
    mpi::MeshLayers layers = mpi::partition_mesh_layers(n, 4, ranks());
    if (ranks() == 1) {
      // One rank cannot leave layers to another: runs that miss layers are refused.
      layers.layers[1] = 9;
      EXPECT_THROW((void)mpi::write_mesh_volume(comm(), layers, ScalarVolume{n, nullptr},
                                                whole.data(), o, dir / "holes.ply"),
                   mpi::RankError);
      continue;
    }
    // Rank 0 empty, and (with three ranks or more) rank 1's run handed to rank 2.
    layers.layers[1] = 0;
    if (ranks() >= 3) layers.layers[2] = 0;
    SCOPED_TRACE(std::string(mesher_name(m)) + (k == 2 ? " analytic gradient" : ""));
    expect_file_of_whole(layers, whole, ScalarVolume{n, nullptr}, o, dir / "holes.ply");
    // The last rank empty: the rank before it holds the top layers.
    layers = mpi::partition_mesh_layers(n, 4, ranks());
    layers.layers[static_cast<std::size_t>(ranks()) - 1] = layers.layers.back();
    expect_file_of_whole(layers, whole, ScalarVolume{n, nullptr}, o, dir / "last.obj");
    if (ranks() >= 4) {
      // An empty run between two others: [0, 5, 5, 10] and so on.
      layers = mpi::partition_mesh_layers(n, 4, ranks());
      layers.layers[2] = layers.layers[1];
      expect_file_of_whole(layers, whole, ScalarVolume{n, nullptr}, o, dir / "middle.glb");
    }
  }
}

TEST(MpiMeshFile, AFailureAnywhereLeavesTheTargetAsItWas) {
  const SharedDir dir;
  const Vec3i n{9, 9, 8 * ranks() + 1};
  std::vector<float> whole = test::wave_volume(n, 4, 3, 0.6, false);
  MeshOptions o;
  o.chunk_edge = 8;
  const mpi::MeshLayers layers = mpi::partition_mesh_layers(n, 8, ranks());
  const std::filesystem::path target = dir / "kept.ply";
  if (rank() == 0) std::ofstream(target) << "the old mesh";
  MPI_Barrier(comm());
  // A NaN in the last rank's cells.
  whole[whole.size() - 9 * 9 * 3 + 40] = std::nanf("");
  std::vector<float> planes = my_planes(layers, whole, n);
  try {
    (void)mpi::write_mesh_volume(comm(), layers, ScalarVolume{n, nullptr}, planes.data(), o,
                                 target);
    ADD_FAILURE() << "no rank failed";
  } catch (const mpi::RankError& e) {
    EXPECT_EQ(e.rank(), ranks() - 1) << e.what();
  }
  // A format no extension names, and a directory that does not exist: refused by every rank.
  whole = test::wave_volume(n, 4, 3, 0.6, false);
  planes = my_planes(layers, whole, n);
  EXPECT_THROW((void)mpi::write_mesh_volume(comm(), layers, ScalarVolume{n, nullptr}, planes.data(),
                                            o, dir / "kept.xyz"),
               mpi::RankError);
  EXPECT_THROW((void)mpi::write_mesh_volume(comm(), layers, ScalarVolume{n, nullptr}, planes.data(),
                                            o, dir / "no" / "such.ply"),
               mpi::RankError);
  MPI_Barrier(comm());
  if (rank() == 0) {
    const std::vector<std::uint8_t> kept = read_bytes(target);
    EXPECT_EQ(std::string(kept.begin(), kept.end()), "the old mesh");
    // No staged file left beside it.
    int files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir / ".")) ++files;
    EXPECT_EQ(files, 1);
  }
}

}  // namespace
}  // namespace voxfield

namespace voxfield {
namespace {

// A world of boxes of four materials with a palette of its own, rotated and scaled by its frame:
// every rank builds the same one.
World framed_boxes() {
  World w(8);
  const std::array<std::array<int, 7>, 5> boxes{{{2, 3, 1, 9, 8, 14, 1},
                                                 {6, 1, 10, 13, 7, 27, 2},
                                                 {0, 6, 20, 4, 11, 33, 3},
                                                 {9, 9, 4, 12, 12, 7, 4},
                                                 {3, 2, 30, 5, 4, 31, 1}}};
  for (const auto& b : boxes)
    for (int z = b[2]; z < b[5]; ++z)
      for (int y = b[1]; y < b[4]; ++y)
        for (int x = b[0]; x < b[3]; ++x) w.voxels.set({x, y, z}, static_cast<std::uint8_t>(b[6]));
  for (int m = 1; m <= 4; ++m)
    w.palette[static_cast<std::size_t>(m)] = {static_cast<std::uint8_t>(50 * m), 20,
                                              static_cast<std::uint8_t>(250 - 40 * m), 255};
  w.frame.origin_world = {10, -4, 0.5};
  w.frame.voxel_size_world = {0.5, 1, 2};
  w.frame.rotation = {{{0, 0, 1}, {1, 0, 0}, {0, 1, 0}}};
  return w;
}

}  // namespace

// A world's surface written by every rank from the slices it holds (write_world_mesh) is the file
// of mesh_world's mesh, for every mesher: layers of 4 planes dealt evenly; from 2 ranks rank 0,
// and from 3 the last rank, without layers; layers of one cell plane cut at uneven planes, as an
// edited world's slabs cut them.
TEST(MpiMeshFile, AWorldsSurfaceIsTheFileOfMeshWorld) {
  const SharedDir dir;
  const World whole = framed_boxes();
  const Box3i lattice = whole.voxels.content_bounds().grown(mesh_world_margin(0));
  for (const Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
    MeshOptions o;
    o.algorithm = m;
    o.chunk_edge = 4;
    const Mesh want = mesh_world(whole, o);
    ASSERT_GT(want.triangle_count(), 100u);
    for (int cut = 0; cut < 3; ++cut) {
      mpi::MeshLayers layers = mpi::partition_mesh_layers(lattice.size(), 4, ranks());
      if (cut == 1 && ranks() >= 2) layers.layers[1] = 0;  // rank 0 without layers
      if (cut == 1 && ranks() >= 3)
        layers.layers[static_cast<std::size_t>(ranks()) - 1] = layers.layers.back();
      if (cut == 2) {  // one cell plane a layer: rank r's rows start at plane 7 r + 3 (r > 0)
        layers.chunk_edge = 1;
        const int cells = lattice.size().z - 1;
        for (int r = 1; r < ranks(); ++r)
          layers.layers[static_cast<std::size_t>(r)] = std::min(7 * r + 3, cells);
        layers.layers.back() = cells;
      }
      // This rank holds only the slices its rows read, as a bounded world.
      World mine(8);
      if (!layers.empty(rank())) {
        const auto [s0, s1] = layers.slab(rank());
        const auto [v0, v1] = mesh_world_slab_voxels(lattice, s0, s1, m);
        Box3i keep = lattice;
        keep.begin.z = v0;
        keep.end.z = v1;
        mine = rechunk_world(whole, 8, keep, "rank");
      }
      const std::filesystem::path path = dir / (std::string("world_") + mesher_name(m) + "_" +
                                                std::to_string(cut) + (cut == 1 ? ".glb" : ".ply"));
      const mpi::MeshFileSummary got =
          mpi::write_world_mesh(comm(), layers, lattice, mine, o, Metric::kEuclidean, path, true);
      expect_summary_and_file(got, want, path);
    }
  }
  // An offset surface is refused on every rank, and nothing is written.
  MeshOptions offset;
  offset.iso = 2;
  const mpi::MeshLayers layers = mpi::partition_mesh_layers(lattice.size(), 32, ranks());
  EXPECT_THROW((void)mpi::write_world_mesh(comm(), layers, lattice, whole, offset,
                                           Metric::kEuclidean, dir / "offset.ply"),
               mpi::RankError);
  EXPECT_FALSE(std::filesystem::exists(dir / "offset.ply"));
}

}  // namespace voxfield
