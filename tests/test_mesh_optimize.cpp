// Simplification and draw-order optimisation (meshoptimizer): the simplified sphere keeps its
// volume and stays within the error limit of the true sphere with about the triangles asked for;
// optimisation keeps the triangles, drops nothing that is used and improves vertex-cache reuse.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <set>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_optimize.h"
#include "voxfield/primitives.h"

using namespace voxfield;

namespace {

Mesh sphere_mesh(double r, std::vector<float>& values) {
  const int n = 48;
  const double h = 0.5, o = -0.5 * (n - 1) * h;
  values.resize(static_cast<std::size_t>(n) * n * n);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x)
        values[static_cast<std::size_t>(x + n * (y + n * z))] =
            static_cast<float>(sdf::sphere({o + x * h, o + y * h, o + z * h}, r));
  ScalarVolume v{Vec3i::splat(n), values.data(), {o, o, o}, {h, h, h}};
  return mesh_volume(v, MeshOptions{});
}

// Average cache miss ratio (vertex transforms per triangle) with a FIFO cache of 16 entries.
double acmr(const Mesh& m) {
  std::deque<std::uint32_t> cache;
  std::size_t misses = 0;
  for (const std::uint32_t i : m.indices) {
    if (std::find(cache.begin(), cache.end(), i) != cache.end()) continue;
    ++misses;
    cache.push_back(i);
    if (cache.size() > 16) cache.pop_front();
  }
  return static_cast<double>(misses) / static_cast<double>(m.triangle_count());
}

}  // namespace

TEST(MeshOptimize, SimplifiedSphereKeepsItsShape) {
  std::vector<float> values;
  const double r = 10;
  const Mesh full = sphere_mesh(r, values);
  SimplifyOptions o;
  o.triangle_ratio = 0.2;
  o.max_error_units = 0.05;
  SimplifyStats st;
  const Mesh simple = simplify_mesh(full, o, &st);
  EXPECT_EQ(st.triangles_before, full.triangle_count());
  EXPECT_EQ(st.triangles_after, simple.triangle_count());
  EXPECT_LE(simple.triangle_count(), full.triangle_count() / 4);
  EXPECT_GE(simple.triangle_count(), full.triangle_count() / 20);
  EXPECT_LE(st.error_units, 0.05 + 1e-6);
  const MeshStats ms = mesh_stats(simple);
  EXPECT_EQ(ms.boundary_edges, 0u);
  EXPECT_NEAR(ms.signed_volume_units3, sdf::sphere_volume(r), 0.02 * sdf::sphere_volume(r));
  for (const auto& p : simple.positions)
    EXPECT_LT(std::abs(Vec3d{p[0], p[1], p[2]}.length() - r), 0.06);
  ASSERT_EQ(simple.normals.size(), simple.vertex_count());
  std::vector<bool> used(simple.vertex_count());
  for (std::uint32_t i : simple.indices) used[i] = true;
  EXPECT_EQ(std::count(used.begin(), used.end(), false), 0);  // unreferenced vertices dropped
  // An error limit alone (ratio 0) simplifies as far as it allows.
  SimplifyOptions by_error;
  by_error.triangle_ratio = 0;
  by_error.max_error_units = 0.05;
  SimplifyStats est;
  const Mesh limited = simplify_mesh(full, by_error, &est);
  EXPECT_LT(limited.triangle_count(), full.triangle_count() / 4);
  EXPECT_LE(est.error_units, 0.05 + 1e-6);
  // A tight error limit wins over the ratio.
  o.max_error_units = 1e-4;
  EXPECT_GT(simplify_mesh(full, o).triangle_count(), full.triangle_count() / 2);
}

TEST(MeshOptimize, OptimizingKeepsTrianglesAndImprovesCacheReuse) {
  std::vector<float> values;
  Mesh m = sphere_mesh(10, values);
  // Scramble the triangle order first, so the chunked order's locality does not help.
  std::vector<std::array<std::uint32_t, 3>> tris(m.triangle_count());
  for (std::size_t t = 0; t < tris.size(); ++t)
    tris[t] = {m.indices[3 * t], m.indices[3 * t + 1], m.indices[3 * t + 2]};
  for (std::size_t t = 0; t < tris.size(); ++t) std::swap(tris[t], tris[(t * 7919) % tris.size()]);
  for (std::size_t t = 0; t < tris.size(); ++t)
    std::copy(tris[t].begin(), tris[t].end(),
              m.indices.begin() + static_cast<std::ptrdiff_t>(3 * t));
  auto triangle_set = [](const Mesh& mesh) {
    std::multiset<std::array<std::array<float, 3>, 3>> s;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
      std::array<std::array<float, 3>, 3> tri{mesh.positions[mesh.indices[3 * t]],
                                              mesh.positions[mesh.indices[3 * t + 1]],
                                              mesh.positions[mesh.indices[3 * t + 2]]};
      std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());
      s.insert(tri);
    }
    return s;
  };
  const auto before = triangle_set(m);
  const double acmr_before = acmr(m);
  optimize_mesh(m);
  EXPECT_TRUE(triangle_set(m) == before);
  EXPECT_LT(acmr(m), 0.8 * acmr_before) << acmr(m) << " vs " << acmr_before;
  EXPECT_TRUE(mesh_stats(m).watertight());
}

TEST(MeshOptimize, BadRequestsAreRefused) {
  Mesh m;
  SimplifyOptions o;
  o.triangle_ratio = -0.1;
  EXPECT_THROW(simplify_mesh(m, o), InvalidArgument);
  o.triangle_ratio = 1.5;
  EXPECT_THROW(simplify_mesh(m, o), InvalidArgument);
  o.triangle_ratio = 0.5;
  o.max_error_units = -1;
  EXPECT_THROW(simplify_mesh(m, o), InvalidArgument);
  m.positions.resize(3);
  m.normals.resize(3);
  m.indices = {0, 1, 7};
  EXPECT_THROW(optimize_mesh(m), InvalidArgument);
  EXPECT_EQ(simplify_mesh(Mesh{}, SimplifyOptions{}).triangle_count(), 0u);
}
