// Caller-allocated mesh outputs (mesh.h): mesh_bound() holds every mesh a lattice can give — the
// fields that cross the most edges included (a checkerboard crosses every one) — and
// mesh_volume_into() / mesh_terrain_into() write exactly mesh_volume() / mesh_terrain()'s arrays,
// or refuse a buffer too small before writing anything.
#include <gtest/gtest.h>

#include <random>

#include "error_text.h"
#include "voxfield/error.h"
#include "voxfield/mesh.h"
#include "voxfield/primitives.h"
#include "voxfield/terrain.h"

namespace voxfield {
namespace mesh_into_test {  // named: unity builds merge the test files

struct Field {
  const char* name;
  Vec3i size;
  std::vector<float> values;
  ScalarVolume volume() const { return {size, values.data()}; }
};

std::vector<Field> fields() {
  std::vector<Field> out;
  const Vec3i n{13, 11, 9};
  const auto count = static_cast<std::size_t>(n.x) * n.y * n.z;
  Field checker{"checkerboard", n, std::vector<float>(count)};
  Field noise{"noise", n, std::vector<float>(count)};
  Field sphere{"sphere", n, std::vector<float>(count)};
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1, 1);
  std::size_t i = 0;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x, ++i) {
        checker.values[i] = (x + y + z) % 2 ? 1.0f + u(rng) * 0.5f : -1.0f + u(rng) * 0.5f;
        noise.values[i] = u(rng);
        sphere.values[i] = static_cast<float>(sdf::sphere({x - 6.0, y - 5.0, z - 4.0}, 3.7));
      }
  out.push_back(std::move(checker));
  out.push_back(std::move(noise));
  out.push_back(std::move(sphere));
  return out;
}

constexpr Mesher kMeshers[] = {Mesher::kMarchingCubes, Mesher::kSurfaceNets,
                               Mesher::kDualContouring};

TEST(MeshInto, EveryMeshFitsItsBoundAndIsWrittenElementForElement) {
  for (const Field& f : fields())
    for (Mesher m : kMeshers)
      for (int chunk : {3, 32}) {
        SCOPED_TRACE(std::string(f.name) + " " + mesher_name(m) + " chunk " +
                     std::to_string(chunk));
        MeshOptions o;
        o.algorithm = m;
        o.chunk_edge = chunk;
        const Mesh want = mesh_volume(f.volume(), o);
        const MeshBound bound = mesh_bound(f.size, m);
        ASSERT_LE(want.vertex_count(), bound.vertices);
        ASSERT_LE(want.indices.size(), bound.indices);
        std::vector<std::array<float, 3>> positions(bound.vertices), normals(bound.vertices);
        std::vector<std::uint32_t> indices(bound.indices);
        const MeshCounts got = mesh_volume_into(f.volume(), o, {positions, normals, {}, indices});
        ASSERT_EQ(got.vertices, want.vertex_count());
        ASSERT_EQ(got.indices, want.indices.size());
        positions.resize(got.vertices);
        normals.resize(got.vertices);
        indices.resize(got.indices);
        EXPECT_EQ(positions, want.positions);
        EXPECT_EQ(normals, want.normals);
        EXPECT_EQ(indices, want.indices);
      }
  // The checkerboard crosses every lattice edge: marching cubes then has a vertex on each, the
  // edge part of its bound.
  const Field checker = fields()[0];
  const Vec3i n = checker.size;
  const std::size_t edges = static_cast<std::size_t>((n.x - 1) * n.y * n.z + n.x * (n.y - 1) * n.z +
                                                     n.x * n.y * (n.z - 1));
  EXPECT_GE(mesh_volume(checker.volume(), {}).vertex_count(), edges);
}

TEST(MeshInto, BuffersTooSmallAreRefusedUntouched) {
  const Field f = fields()[2];
  const Mesh want = mesh_volume(f.volume(), {});
  const std::array<float, 3> sentinel{-7, -7, -7};
  for (int short_one = 0; short_one < 3; ++short_one) {
    std::vector<std::array<float, 3>> positions(want.vertex_count() - (short_one == 0), sentinel),
        normals(want.vertex_count() - (short_one == 1), sentinel);
    std::vector<std::uint32_t> indices(want.indices.size() - (short_one == 2), 77);
    const std::string e = test::error_of([&] {
      mesh_volume_into(f.volume(), {}, {positions, normals, {}, indices});
    });
    EXPECT_NE(e.find("needs " + std::to_string(want.vertex_count()) + " positions"),
              std::string::npos)
        << e;
    EXPECT_NE(e.find("mesh_bound"), std::string::npos) << e;
    for (const auto& p : positions) ASSERT_EQ(p, sentinel);
    for (const auto& p : normals) ASSERT_EQ(p, sentinel);
    for (std::uint32_t i : indices) ASSERT_EQ(i, 77u);
  }
  EXPECT_THROW(mesh_bound({1, 5, 5}, Mesher::kMarchingCubes), InvalidArgument);
  // Counts past 64 bits saturate: no buffer meets the bound, rather than a small wrapped one.
  const int huge = 2000000000;
  EXPECT_EQ(mesh_bound({huge, huge, huge}, Mesher::kMarchingCubes).indices, UINT64_MAX);
  EXPECT_EQ(mesh_bound({huge, huge, huge}, Mesher::kSurfaceNets).vertices, UINT64_MAX);
}

TEST(MeshInto, TerrainsWithColours) {
  TerrainOptions o;
  o.samples = {30, 26, 20};
  Palette palette{};
  palette[4] = {10, 200, 30, 255};
  palette[9] = {240, 20, 20, 255};
  o.palette = palette;
  TerrainField t(o);
  t.assign([](const Vec3d& p) { return p.z - 9 - 2 * std::sin(p.x / 4); }, 4);
  TerrainBrush b;
  b.centre_units = {15, 13, 9};
  b.radius_units = 4;
  b.material = 9;
  t.apply(b);
  for (Mesher m : kMeshers) {
    MeshOptions mo;
    mo.algorithm = m;
    const Mesh want = mesh_terrain(t, mo);
    const MeshBound bound = mesh_bound(t.size(), m);
    std::vector<std::array<float, 3>> positions(bound.vertices), normals(bound.vertices);
    std::vector<std::array<std::uint8_t, 3>> colors(bound.vertices);
    std::vector<std::uint32_t> indices(bound.indices);
    const MeshCounts got = mesh_terrain_into(t, mo, {positions, normals, colors, indices});
    positions.resize(got.vertices);
    colors.resize(got.vertices);
    indices.resize(got.indices);
    EXPECT_EQ(positions, want.positions) << mesher_name(m);
    EXPECT_EQ(colors, want.colors) << mesher_name(m);
    EXPECT_EQ(indices, want.indices) << mesher_name(m);
    // A colour array one short is refused before anything is written.
    std::vector<std::array<float, 3>> p2(want.vertex_count()), n2(want.vertex_count());
    std::vector<std::array<std::uint8_t, 3>> c2(want.vertex_count() - 1, {7, 7, 7});
    std::vector<std::uint32_t> i2(want.indices.size());
    EXPECT_NE(test::error_of([&] {
                mesh_terrain_into(t, mo, {p2, n2, c2, i2});
              }).find("colours"),
              std::string::npos);
    for (const auto& c : c2) ASSERT_EQ(c, (std::array<std::uint8_t, 3>{7, 7, 7}));
  }
}

}  // namespace mesh_into_test
}  // namespace voxfield
