// Slabs of a voxel world's surface (mesh_slab.h: mesh_world_slab), each computed from a world cut
// to exactly the slices it reads, against mesh_world over the whole world: laid end to end they are
// its arrays bit for bit — positions, normals, colours, triangles — for every mesher and cut,
// bounded and unbounded worlds, content at the bounds, a frame; bad requests refused by name.
#include <gtest/gtest.h>

#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "error_text.h"
#include "voxfield/error.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/world_io.h"

using namespace voxfield;

namespace {

// A world of random boxes and single voxels of materials 1..4 with a palette of its own; `bounds`
// (if any) are touched by the content on some faces.
World random_world(std::uint32_t seed, std::optional<Box3i> bounds) {
  World w(8, bounds);
  std::mt19937 rng(seed);
  const Box3i space = bounds.value_or(Box3i{{-3, 2, -5}, {21, 19, 30}});
  std::uniform_int_distribution<int> mat(1, 4);
  auto in = [&](int a) {
    return std::uniform_int_distribution<int>(space.begin[a], space.end[a] - 1)(rng);
  };
  for (int i = 0; i < 12; ++i) {
    const Vec3i c{in(0), in(1), in(2)};
    const int r = std::uniform_int_distribution<int>(0, 3)(rng);
    const std::uint8_t m = static_cast<std::uint8_t>(mat(rng));
    for (int z = c.z - r; z <= c.z + r; ++z)
      for (int y = c.y - r; y <= c.y + r; ++y)
        for (int x = c.x - r; x <= c.x + r; ++x)
          if (space.contains(Vec3i{x, y, z})) w.voxels.set({x, y, z}, m);
  }
  for (int m = 1; m <= 4; ++m)
    w.palette[static_cast<std::size_t>(m)] = {static_cast<std::uint8_t>(40 * m),
                                              static_cast<std::uint8_t>(200 - 30 * m),
                                              static_cast<std::uint8_t>(17 * m), 255};
  return w;
}

// mesh_world's lattice (the content grown by its margin at iso 0).
Box3i lattice_of(const World& w) {
  return w.voxels.content_bounds().grown(mesh_world_margin(0));
}

// The rows [z0, z1) from a bounded copy of only the slices the slab reads (whatever lies beyond
// is left out: a read past them would change the mesh).
MeshSlab world_slab_of(const World& w, const MeshOptions& o, int z0, int z1) {
  const Box3i lattice = lattice_of(w);
  const auto [v0, v1] = mesh_world_slab_voxels(lattice, z0, z1, o.algorithm);
  Box3i keep = lattice;
  keep.begin.z = v0;
  keep.end.z = v1;
  if (w.voxels.bounds()) keep = keep.intersect(*w.voxels.bounds());
  World part = rechunk_world(w, 8, keep, "slab");
  part.palette = w.palette;
  part.frame = w.frame;
  return mesh_world_slab(part, lattice, o, Metric::kEuclidean, z0, z1);
}

// The slabs cut at `cuts` (0 = c0 < ... < ck = the lattice's planes) laid end to end.
Mesh laid_end_to_end(const World& w, const MeshOptions& o, const std::vector<int>& cuts) {
  Mesh all;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const MeshSlab s = world_slab_of(w, o, cuts[k], cuts[k + 1]);
    EXPECT_EQ(s.part.colors.size(), s.part.positions.size());
    const std::size_t first = all.positions.size();
    const auto owned = static_cast<std::ptrdiff_t>(s.owned_vertices);
    all.positions.insert(all.positions.end(), s.part.positions.begin(),
                         s.part.positions.begin() + owned);
    all.normals.insert(all.normals.end(), s.part.normals.begin(), s.part.normals.begin() + owned);
    all.colors.insert(all.colors.end(), s.part.colors.begin(), s.part.colors.begin() + owned);
    for (const std::uint32_t i : s.part.indices)
      all.indices.push_back(static_cast<std::uint32_t>(s.number(i, first)));
  }
  return all;
}

void expect_same_arrays(const Mesh& got, const Mesh& want, const std::string& what) {
  SCOPED_TRACE(what);
  ASSERT_EQ(got.positions.size(), want.positions.size());
  ASSERT_EQ(got.indices.size(), want.indices.size());
  EXPECT_TRUE(got.positions == want.positions);
  EXPECT_TRUE(got.normals == want.normals);
  EXPECT_TRUE(got.colors == want.colors);
  EXPECT_TRUE(got.indices == want.indices);
}

// The refusal's message holds `words`.
void expect_refused(const std::function<void()>& call, const std::string& words) {
  const std::string said = test::error_of(call);
  EXPECT_NE(said.find(words), std::string::npos) << said;
}

}  // namespace

TEST(MeshWorldSlab, SlabsLaidEndToEndAreMeshWorldsArrays) {
  VoxelFrame turned;
  turned.origin_world = {1.5, -2, 0.25};
  turned.voxel_size_world = {0.5, 0.5, 2};
  turned.rotation = {{{0, -1, 0}, {1, 0, 0}, {0, 0, 1}}};
  struct Case {
    std::uint32_t seed;
    std::optional<Box3i> bounds;
    bool framed;
  };
  const std::vector<Case> cases{{1, std::nullopt, false},
                                {2, Box3i{{0, 0, 0}, {18, 15, 26}}, false},
                                {3, Box3i{{-4, 1, 3}, {14, 20, 24}}, true}};
  for (const Case& c : cases) {
    World w = random_world(c.seed, c.bounds);
    if (c.framed) w.frame = turned;
    const int nz = lattice_of(w).size().z;
    ASSERT_GE(nz, 12);
    for (const Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
      MeshOptions o;
      o.algorithm = m;
      const Mesh whole = mesh_world(w, o);
      ASSERT_GT(whole.indices.size(), 300u);
      const std::string what = "seed " + std::to_string(c.seed) + ", " + mesher_name(m);
      // One slab; cuts one plane apart, where the slabs' reads overlap most; uneven cuts.
      expect_same_arrays(laid_end_to_end(w, o, {0, nz}), whole, what + ", one slab");
      expect_same_arrays(laid_end_to_end(w, o, {0, 1, 2, 3, nz - 2, nz - 1, nz}), whole,
                         what + ", thin slabs");
      expect_same_arrays(laid_end_to_end(w, o, {0, 5, nz / 2, nz / 2 + 7, nz}), whole,
                         what + ", uneven slabs");
    }
  }
}

TEST(MeshWorldSlab, BadRequestsAreRefused) {
  const World w = random_world(4, std::nullopt);
  const Box3i lattice = lattice_of(w);
  MeshOptions o;
  o.iso = 2;
  expect_refused([&] { (void)mesh_world_slab(w, lattice, o, Metric::kEuclidean, 0, 3); },
                 "is meshed at iso 0");
  o.iso = 0;
  expect_refused([&] { (void)mesh_world_slab(w, lattice, o, Metric::kEuclidean, 3, 3); },
                 "are not a slab of the lattice's");
  expect_refused(
      [&] { (void)mesh_world_slab(w, lattice, o, Metric::kEuclidean, 0, lattice.size().z + 1); },
      "are not a slab");
  Box3i flat = lattice;
  flat.end.y = flat.begin.y + 1;
  expect_refused([&] { (void)mesh_world_slab(w, flat, o, Metric::kEuclidean, 0, 1); },
                 "at least 2 samples");
  o.gradient = [](const std::array<double, 3>&) { return std::array<double, 3>{0, 0, 1}; };
  expect_refused([&] { (void)mesh_world_slab(w, lattice, o, Metric::kEuclidean, 0, 3); },
                 "analytic value or gradient");
}
