// Marching cubes on the GPU (gpu_mesh.h) against the CPU's: the same triangles — every triangle's
// three positions and normals equal bit for bit, in the same winding — for analytic shapes, random
// fields that hit every ambiguous case, both pyramids, both inside conventions, and the terrain
// field in its three widths; under the validation layer (synchronisation validation included).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <random>

#include "gpu_suite.h"
#include "voxfield/gpu_mesh.h"
#include "voxfield/primitives.h"

using namespace voxfield;

// A named namespace: unity builds put the GPU suites into one translation unit.
namespace gpu_mesh_test {

// Each triangle as its three (position, normal) corners — the floats' bits, so that -0 and +0
// differ — rotated to start at the smallest corner (orientation kept), the list sorted: two
// meshes with the same triangles give equal lists.
using Corner = std::array<std::uint32_t, 6>;
std::vector<std::array<Corner, 3>> triangles(const Mesh& m) {
  std::vector<std::array<Corner, 3>> out(m.triangle_count());
  for (std::size_t t = 0; t < out.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = m.indices[3 * t + static_cast<std::size_t>(k)];
      const auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
      out[t][static_cast<std::size_t>(k)] = {bits(m.positions[v][0]), bits(m.positions[v][1]),
                                             bits(m.positions[v][2]), bits(m.normals[v][0]),
                                             bits(m.normals[v][1]),   bits(m.normals[v][2])};
    }
    std::rotate(out[t].begin(), std::min_element(out[t].begin(), out[t].end()), out[t].end());
  }
  std::sort(out.begin(), out.end());
  return out;
}

void expect_same_triangles(const Mesh& gpu, const Mesh& cpu) {
  ASSERT_EQ(gpu.triangle_count(), cpu.triangle_count());
  const auto a = triangles(gpu), b = triangles(cpu);
  std::size_t differ = 0;
  for (std::size_t i = 0; i < a.size(); ++i) differ += a[i] != b[i];
  EXPECT_EQ(differ, 0u) << "of " << a.size() << " triangles";
}

struct Volume {
  Vec3i size;
  std::vector<float> values;
  ScalarVolume view() const {
    ScalarVolume v;
    v.size = size;
    v.values = values.data();
    v.origin_units = {-1.5, 2.25, 0.5};
    v.spacing_units = {0.5, 0.75, 1.0};
    return v;
  }
};

std::vector<std::pair<const char*, Volume>> volumes() {
  std::vector<std::pair<const char*, Volume>> out;
  const Vec3i n{21, 17, 15};
  Volume sphere{n, {}}, torus{n, {}}, noise{n, {}};
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-1, 1);
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        const Vec3d p{x - 10.2, y - 8.1, z - 7.3};
        sphere.values.push_back(static_cast<float>(sdf::sphere(p, 6.3)));
        torus.values.push_back(static_cast<float>(sdf::torus(p, 5.0, 2.1)));
        noise.values.push_back(u(rng));  // every case, the ambiguous ones many times
      }
  out.emplace_back("sphere", std::move(sphere));
  out.emplace_back("torus", std::move(torus));
  out.emplace_back("noise", std::move(noise));
  return out;
}

TEST(GpuMesh, MarchingCubesEqualTheCpusTriangles) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  for (const auto& [name, volume] : volumes())
    for (gpu::Pyramid pyramid : {gpu::Pyramid::kFourToOne, gpu::Pyramid::kEightToOne})
      for (bool above : {false, true}) {
        SCOPED_TRACE(std::string(name) +
                     (pyramid == gpu::Pyramid::kFourToOne ? " 4-to-1" : " 8-to-1") +
                     (above ? " inside above" : ""));
        MeshOptions o;
        o.iso = above ? -0.05 : 0.05;
        o.inside_above = above;
        gpu::GpuMeshOptions g;
        g.pyramid = pyramid;
        gpu::GpuMeshStats st;
        const Mesh got = gpu::marching_cubes(*ctx, volume.view(), o, g, &st);
        const Mesh want = mesh_volume(volume.view(), o);
        ASSERT_GT(want.triangle_count(), 100u);
        expect_same_triangles(got, want);
        EXPECT_EQ(st.triangles, want.triangle_count());
        // One submission computes everything (classify, every level, the arguments, the
        // traversal); one more reads the triangles back.
        EXPECT_EQ(st.submits, 2);
        EXPECT_EQ(st.dispatches, st.pyramid_levels + 2);  // classify, levels - 1, args, traverse
        // 72 bytes of positions and normals and 24 of vertex elements per triangle.
        EXPECT_EQ(st.bytes_downloaded, static_cast<std::int64_t>(st.triangles) * 96);
        // Vertices shared as the CPU shares them: the same count, a closed mesh where it is.
        EXPECT_EQ(got.vertex_count(), want.vertex_count());
        EXPECT_EQ(mesh_stats(got).watertight(), mesh_stats(want).watertight());
        voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
      }
}

TEST(GpuMesh, TerrainFieldsInEveryWidth) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  for (TerrainStorage storage : {TerrainStorage::kI8, TerrainStorage::kI16, TerrainStorage::kF32})
    for (bool positive_inside : {false, true}) {
      SCOPED_TRACE(std::string(terrain_storage_name(storage)) +
                   (positive_inside ? " +inside" : ""));
      TerrainOptions to;
      to.samples = {37, 29, 23};  // sample counts that do not fill the packed words evenly
      to.storage = storage;
      to.spacing_units = 0.5;
      to.origin_units = {1, -2, 0.25};
      to.positive_inside = positive_inside;
      TerrainField t(to);
      const double sign = positive_inside ? -1 : 1;
      t.assign([&](const Vec3d& p) {
        return sign * (p.z - 5 - 1.5 * std::sin(p.x) * std::cos(p.y / 2));
      });
      TerrainBrush b;
      b.centre_units = {10, 5, 5};
      b.radius_units = 3;
      b.smooth_units = 1;
      t.apply(b);
      gpu::GpuMeshStats st;
      const Mesh got = gpu::marching_cubes(*ctx, t, {}, &st);
      MeshOptions mo;
      const Mesh want = mesh_terrain(t, mo);
      ASSERT_GT(want.triangle_count(), 500u);
      expect_same_triangles(got, want);
      // The samples travel in their width: i8 four per word, i16 two.
      const std::int64_t samples = 37 * 29 * 23;
      const int per_word = storage == TerrainStorage::kI8    ? 4
                           : storage == TerrainStorage::kI16 ? 2
                                                             : 1;
      EXPECT_EQ(st.samples_bytes, (samples + per_word - 1) / per_word * 4);
      EXPECT_EQ(st.field_width, terrain_storage_name(storage));
      voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
    }
}

TEST(GpuMesh, EmptySurfacesTooSmallBuffersAndBadRequests) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  auto vols = volumes();
  const ScalarVolume sphere = vols[0].second.view();
  // No surface: no triangles, nothing read back beyond the count.
  MeshOptions o;
  o.iso = 1000;
  gpu::GpuMeshStats st;
  EXPECT_EQ(gpu::marching_cubes(*ctx, sphere, o, {}, &st).triangle_count(), 0u);
  EXPECT_EQ(st.bytes_downloaded, 0);
  // A vertex buffer too small: refused with both counts.
  gpu::GpuMeshOptions small;
  small.max_triangles = 10;
  try {
    gpu::marching_cubes(*ctx, sphere, {}, small);
    ADD_FAILURE() << "a vertex buffer of 10 triangles was accepted";
  } catch (const ResourceLimitError& e) {
    EXPECT_NE(std::string(e.what()).find("holds 10"), std::string::npos) << e.what();
  }
  MeshOptions with_value;
  with_value.value = [](const std::array<double, 3>&) { return 0.0; };
  EXPECT_THROW(gpu::marching_cubes(*ctx, sphere, with_value), InvalidArgument);
  std::vector<float> nan(8, 0.0f);
  nan[3] = std::nanf("");
  ScalarVolume bad;
  bad.size = {2, 2, 2};
  bad.values = nan.data();
  EXPECT_THROW(gpu::marching_cubes(*ctx, bad, {}), InvalidArgument);
  bad.size = {1, 2, 2};
  EXPECT_THROW(gpu::marching_cubes(*ctx, bad, {}), InvalidArgument);
  voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

}  // namespace gpu_mesh_test

namespace gpu_mesh_test {

// Past the device's x limit of workgroups (lavapipe: 65535 x 64 = 4 194 240 cells): the passes
// stride over the rest (a dispatch split over y lost its second row's cells on lavapipe).
TEST(GpuMesh, VolumesPastOneDispatchRow) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  const Vec3i n{2100, 2100, 2};  // 4 410 000 cells
  std::vector<float> v(static_cast<std::size_t>(n.x) * n.y * n.z);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = (i * 2654435761u % 1000) < 3 ? -1.0f : 1.0f;
  ScalarVolume sv;
  sv.size = n;
  sv.values = v.data();
  const Mesh want = mesh_volume(sv, {});
  for (gpu::Pyramid p : {gpu::Pyramid::kFourToOne, gpu::Pyramid::kEightToOne}) {
    gpu::GpuMeshOptions g;
    g.pyramid = p;
    expect_same_triangles(gpu::marching_cubes(*ctx, sv, {}, g), want);
  }
  voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

}  // namespace gpu_mesh_test
