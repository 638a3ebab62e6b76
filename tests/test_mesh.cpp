// The meshers against analytic shapes (topology, enclosed volume and area, distance of every vertex
// to the true surface, orientation), exact counts on voxel blocks, every corner configuration of a
// cell and of random lattices (closed, oriented 2-manifolds), and independence from the chunk edge
// and the thread count (the same triangle set).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "mesh_compare.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/parallel.h"
#include "voxfield/primitives.h"

using namespace voxfield;

namespace {

const Mesher kMeshers[] = {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring};

// An analytic field sampled on n^3 points spaced `h` apart, centred on the origin.
struct Sampled {
  std::vector<float> values;
  ScalarVolume volume;
  Sampled(int n, double h, const std::function<double(Vec3d)>& f) {
    values.resize(static_cast<std::size_t>(n) * n * n);
    const double o = -0.5 * (n - 1) * h;
    for (int z = 0; z < n; ++z)
      for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
          values[static_cast<std::size_t>(x + n * (y + n * z))] =
              static_cast<float>(f({o + x * h, o + y * h, o + z * h}));
    volume.size = Vec3i::splat(n);
    volume.values = values.data();
    volume.origin_units = {o, o, o};
    volume.spacing_units = {h, h, h};
  }
};

Vec3d at(const std::array<float, 3>& p) {
  return {p[0], p[1], p[2]};
}

MeshOptions with(Mesher m, int chunk_edge = 32) {
  MeshOptions o;
  o.algorithm = m;
  o.chunk_edge = chunk_edge;
  return o;
}

// Each triangle as its three positions, rotated to start at the smallest (orientation kept).
using Tri = std::array<std::array<float, 3>, 3>;
std::multiset<Tri> triangle_set(const Mesh& m) {
  std::multiset<Tri> s;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    Tri tri{m.positions[m.indices[3 * t]], m.positions[m.indices[3 * t + 1]],
            m.positions[m.indices[3 * t + 2]]};
    const auto first = std::min_element(tri.begin(), tri.end()) - tri.begin();
    std::rotate(tri.begin(), tri.begin() + first, tri.end());
    s.insert(tri);
  }
  return s;
}

void expect_closed_manifold(const Mesh& m, std::int64_t euler, const char* what) {
  const MeshStats s = mesh_stats(m);
  EXPECT_GT(s.triangles, 0u) << what;
  EXPECT_EQ(s.boundary_edges, 0u) << what;
  EXPECT_EQ(s.nonmanifold_edges, 0u) << what;
  EXPECT_EQ(s.misoriented_edges, 0u) << what;
  EXPECT_EQ(s.degenerate_triangles, 0u) << what;
  EXPECT_EQ(s.euler_characteristic, euler) << what;
  EXPECT_GT(s.signed_volume_units3, 0) << what << ": triangles face inwards";
  std::vector<bool> used(m.vertex_count());
  for (std::uint32_t i : m.indices) used[i] = true;
  EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << what << ": unreferenced vertices";
}

}  // namespace

// A sphere of radius 10 on a grid of spacing 0.5: closed genus-0 surface, volume and area close to
// the analytic ones, every vertex near the sphere, normals radial.
TEST(Mesh, SphereIsAClosedSurfaceNearTheTrueOne) {
  const double r = 10;
  Sampled s(48, 0.5, [&](Vec3d p) { return sdf::sphere(p, r); });
  for (Mesher m : kMeshers) {
    SCOPED_TRACE(mesher_name(m));
    const Mesh mesh = mesh_volume(s.volume, with(m, 16));
    expect_closed_manifold(mesh, 2, "sphere");
    const MeshStats st = mesh_stats(mesh);
    // Inscribed polyhedra lose a little volume and area: within 1 % at 20 samples per radius.
    EXPECT_NEAR(st.signed_volume_units3, sdf::sphere_volume(r), 0.01 * sdf::sphere_volume(r));
    EXPECT_NEAR(st.area_units2, sdf::sphere_area(r), 0.01 * sdf::sphere_area(r));
    // Marching cubes interpolates an exact distance along edges: within 1 % of the spacing. Surface
    // nets averages crossings, which sits inside a convex surface by up to ~ h^2 / r; dual
    // contouring's tangent planes meet just outside it.
    const double tolerance = m == Mesher::kMarchingCubes ? 0.005 : 0.05;
    double worst = 0, worst_normal = 1;
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
      const Vec3d p = at(mesh.positions[i]);
      worst = std::max(worst, std::abs(p.length() - r));
      worst_normal = std::min(worst_normal, dot(at(mesh.normals[i]), p.normalized()));
    }
    EXPECT_LT(worst, tolerance);
    EXPECT_GT(worst_normal, 0.999);
  }
}

TEST(Mesh, TorusHasEulerCharacteristicZero) {
  const double major = 8, minor = 3;
  Sampled s(48, 0.5, [&](Vec3d p) { return sdf::torus(p, major, minor); });
  for (Mesher m : kMeshers) {
    SCOPED_TRACE(mesher_name(m));
    const Mesh mesh = mesh_volume(s.volume, with(m, 8));
    expect_closed_manifold(mesh, 0, "torus");
    const MeshStats st = mesh_stats(mesh);
    EXPECT_NEAR(st.signed_volume_units3, sdf::torus_volume(major, minor),
                0.02 * sdf::torus_volume(major, minor));
    EXPECT_NEAR(st.area_units2, sdf::torus_area(major, minor),
                0.02 * sdf::torus_area(major, minor));
  }
}

TEST(Mesh, CapsuleAndBoxAreClosedWithTheirVolume) {
  const Vec3d a{-5, -2, 1}, b{4, 3, -1};
  const double radius = 3, length = (b - a).length();
  Sampled capsule(40, 0.5, [&](Vec3d p) { return sdf::capsule(p, a, b, radius); });
  Sampled box(40, 0.5, [&](Vec3d p) { return sdf::box(p, {6.3, 4.2, 3.1}); });
  for (Mesher m : kMeshers) {
    SCOPED_TRACE(mesher_name(m));
    const Mesh c = mesh_volume(capsule.volume, with(m));
    expect_closed_manifold(c, 2, "capsule");
    EXPECT_NEAR(mesh_stats(c).signed_volume_units3, sdf::capsule_volume(length, radius),
                0.02 * sdf::capsule_volume(length, radius));
    const Mesh bx = mesh_volume(box.volume, with(m));
    expect_closed_manifold(bx, 2, "box");
    // Both meshers bevel the box's edges by up to half a cell: within 3 % of 8 * 6.3 * 4.2 * 3.1.
    EXPECT_NEAR(mesh_stats(bx).signed_volume_units3, 8 * 6.3 * 4.2 * 3.1,
                0.03 * 8 * 6.3 * 4.2 * 3.1);
  }
}

// Surface nets of a filled 6^3 block: one quad per exposed voxel face, 6 * 36 = 216.
TEST(Mesh, SurfaceNetsOfABlockHasOneQuadPerVoxelFace) {
  World w(16);
  w.voxels.fill(Box3i::from_size({6, 6, 6}), 7);
  const Mesh sn = mesh_world(w, with(Mesher::kSurfaceNets));
  EXPECT_EQ(sn.triangle_count(), 2u * 216);
  expect_closed_manifold(sn, 2, "block, surface nets");
  const Mesh mc = mesh_world(w, with(Mesher::kMarchingCubes));
  expect_closed_manifold(mc, 2, "block, marching cubes");
  // Dual contouring with the faces' exact normals rebuilds the block itself: its 8 corners are
  // vertices, every vertex lies on a face of [0, 6]^3, and the volume is exactly 216.
  const Mesh dc = mesh_world(w, with(Mesher::kDualContouring));
  EXPECT_EQ(dc.triangle_count(), 2u * 216);
  EXPECT_NEAR(mesh_stats(dc).signed_volume_units3, 216.0, 1e-3);
  int corners = 0;
  for (const auto& p : dc.positions) {
    int on_face = 0, at_corner = 0;
    for (int a = 0; a < 3; ++a) {
      const float c = p[static_cast<std::size_t>(a)];
      on_face += c == 0.0f || c == 6.0f;
      at_corner += c == 0.0f || c == 6.0f;
    }
    EXPECT_GE(on_face, 1);
    corners += at_corner == 3;
  }
  EXPECT_EQ(corners, 8);
  // The block's 8 corner voxels cut off by one triangle each, the rest two per voxel face.
  const Rgba c = w.palette[7];
  for (const auto& col : sn.colors) EXPECT_EQ(col, (std::array<std::uint8_t, 3>{c.r, c.g, c.b}));
  // Surfaces run halfway between voxel centres: on the block's faces, at 0 and 6 (+-0.5 margins).
  for (const auto& p : mc.positions)
    for (int a = 0; a < 3; ++a)
      EXPECT_TRUE(p[static_cast<std::size_t>(a)] >= -0.01f &&
                  p[static_cast<std::size_t>(a)] <= 6.01f);
}

// A world's offset surfaces take the shape of the metric's ball: around one voxel at iso r the
// Chebyshev surface is the box of half-size r about its centre, the Manhattan one the octahedron
// |x| + |y| + |z| = r (marching cubes is exact there: the field is linear in every cell), the
// Euclidean one the sphere of radius r; colours are the nearest voxel's; normals and dual
// contouring's Hermite data come from the exact nearest sites. At iso 0 every metric gives the
// same mesh, and a negative iso insets a block by the metric's distance.
TEST(Mesh, WorldOffsetSurfacesAreTheMetricsBalls) {
  World w(16);
  w.voxels.set({10, 10, 10}, 9);
  const Rgba c = w.palette[9];
  constexpr double kPi = 3.14159265358979323846;
  for (double r : {2.0, 3.5}) {
    SCOPED_TRACE(r);
    MeshOptions o = with(Mesher::kMarchingCubes);
    o.iso = r;
    const Mesh box = mesh_world(w, o, Metric::kChebyshev);
    const Mesh octahedron = mesh_world(w, o, Metric::kManhattan);
    const Mesh sphere = mesh_world(w, o, Metric::kEuclidean);
    for (const Mesh* m : {&box, &octahedron, &sphere}) {
      expect_closed_manifold(*m, 2, "offset surface");
      for (const auto& col : m->colors)
        ASSERT_EQ(col, (std::array<std::uint8_t, 3>{c.r, c.g, c.b}));
    }
    // The box's faces are exact; marching cubes bevels its edges and corners within the cells
    // they cross. With f the fraction of a cell the faces lie past the last samples inside (1
    // when r is a whole number: the faces run through samples), each of the 12 edges (length 2r)
    // loses a triangle of area f^2 / 2 in section, and the 8 corners give back less than f^3.
    const double f = r - std::ceil(r) + 1, cube = std::pow(2 * r, 3);
    const double bevelled = cube - 12 * (2 * r) * f * f / 2;
    EXPECT_GE(mesh_stats(box).signed_volume_units3, bevelled - 1e-3);
    EXPECT_LE(mesh_stats(box).signed_volume_units3, bevelled + 8 * f * f * f);
    EXPECT_NEAR(mesh_stats(octahedron).signed_volume_units3, 4.0 / 3 * r * r * r, 1e-3);
    for (const auto& p : octahedron.positions) {
      const Vec3d d = at(p) - Vec3d{10.5, 10.5, 10.5};
      EXPECT_NEAR(std::abs(d.x) + std::abs(d.y) + std::abs(d.z), r, 1e-4);
    }
    // The sphere's crossings interpolate the distance linearly along edges (within 1 / (8r) of
    // the true sphere); its flat facets cut inside it, more so the smaller it is.
    for (const auto& p : sphere.positions)
      EXPECT_NEAR((at(p) - Vec3d{10.5, 10.5, 10.5}).length(), r, 1 / (8 * r) + 1e-4);
    const double ball = 4.0 / 3 * kPi * r * r * r;
    EXPECT_GE(mesh_stats(sphere).signed_volume_units3, 0.8 * ball);
    EXPECT_LE(mesh_stats(sphere).signed_volume_units3, ball);
  }
  // Hermite data from the exact nearest sites: dual contouring rebuilds the box's sharp edges and
  // corners exactly, and every normal of the sphere is radial.
  for (double r : {2.0, 3.5}) {
    SCOPED_TRACE(r);
    MeshOptions o = with(Mesher::kDualContouring);
    o.iso = r;
    const Mesh box = mesh_world(w, o, Metric::kChebyshev);
    expect_closed_manifold(box, 2, "offset box, dual contouring");
    EXPECT_NEAR(mesh_stats(box).signed_volume_units3, std::pow(2 * r, 3), 1e-3);
    int corners = 0;
    for (const auto& p : box.positions) {
      const Vec3d d = at(p) - Vec3d{10.5, 10.5, 10.5};
      corners += std::abs(std::abs(d.x) - r) < 1e-4 && std::abs(std::abs(d.y) - r) < 1e-4 &&
                 std::abs(std::abs(d.z) - r) < 1e-4;
    }
    EXPECT_EQ(corners, 8);
    // (The octahedron's slanted faces are not rebuilt so: its ridges run along cell faces, where
    // dual contouring's one vertex per cell cannot sit on both sides; it stays closed.)
    expect_closed_manifold(mesh_world(w, o, Metric::kManhattan), 2, "octahedron, dual contouring");
    o.algorithm = Mesher::kMarchingCubes;
    const Mesh sphere = mesh_world(w, o, Metric::kEuclidean);
    for (std::size_t i = 0; i < sphere.positions.size(); ++i) {
      const Vec3d radial = (at(sphere.positions[i]) - Vec3d{10.5, 10.5, 10.5}).normalized();
      EXPECT_GT(dot(at(sphere.normals[i]), radial), 1 - 1e-6);
    }
  }
  // At iso 0 the voxels' own surface, whatever the metric.
  const Mesh e = mesh_world(w, with(Mesher::kMarchingCubes), Metric::kEuclidean);
  const Mesh m = mesh_world(w, with(Mesher::kMarchingCubes), Metric::kManhattan);
  EXPECT_EQ(e.positions, m.positions);
  EXPECT_EQ(e.indices, m.indices);
  // Inset: a 9^3 block at iso -2 (Chebyshev) is the box of voxel centres two from the air, [1.5,
  // 7.5]^3 in world units (side 6, faces through samples: f = 1), bevelled as above.
  World block(16);
  block.voxels.fill(Box3i::from_size({9, 9, 9}), 4);
  MeshOptions inset = with(Mesher::kMarchingCubes);
  inset.iso = -2;
  const Mesh inner = mesh_world(block, inset, Metric::kChebyshev);
  expect_closed_manifold(inner, 2, "inset");
  EXPECT_GE(mesh_stats(inner).signed_volume_units3, 216 - 12 * 6 * 0.5 - 1e-3);
  EXPECT_LE(mesh_stats(inner).signed_volume_units3, 216 - 12 * 6 * 0.5 + 8);
  for (const auto& p : inner.positions)
    for (int a = 0; a < 3; ++a) {
      EXPECT_GE(p[static_cast<std::size_t>(a)], 1.5f - 1e-4f);
      EXPECT_LE(p[static_cast<std::size_t>(a)], 7.5f + 1e-4f);
    }
  MeshOptions bad = with(Mesher::kMarchingCubes);
  bad.iso = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(mesh_world(w, bad), InvalidArgument);
  bad.iso = 1e6;
  EXPECT_THROW(mesh_world(w, bad), InvalidArgument);
  bad.iso = 0.5;  // between a solid and an air centre: no offset surface of its own
  EXPECT_THROW(mesh_world(w, bad), InvalidArgument);
}

// Two voxels touching at a corner only: the dual meshers' vertex sits on a saddle of the
// interpolant (no gradient), and still gets a unit normal.
TEST(Mesh, NormalsAreUnitLengthEvenOnSaddles) {
  World w(8);
  w.voxels.set({0, 0, 0}, 1);
  w.voxels.set({1, 1, 1}, 1);
  for (Mesher m : kMeshers) {
    const Mesh mesh = mesh_world(w, with(m));
    ASSERT_GT(mesh.vertex_count(), 0u);
    for (const auto& n : mesh.normals) EXPECT_NEAR(at(n).length(), 1.0, 1e-5) << mesher_name(m);
  }
}

// Every one of the 256 corner configurations of a lone cell, with random magnitudes (so ambiguous
// faces go both ways), inside a lattice of outside samples: a closed, oriented surface each time.
TEST(Mesh, EveryCellConfigurationGivesAClosedOrientedSurface) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> magnitude(0.05f, 1.0f);
  for (unsigned mask = 1; mask < 256; ++mask)
    for (int trial = 0; trial < 8; ++trial) {
      std::vector<float> v(4 * 4 * 4, 1.0f);
      for (int c = 0; c < 8; ++c) {
        const int x = 1 + (c & 1), y = 1 + (c >> 1 & 1), z = 1 + (c >> 2 & 1);
        const float m = magnitude(rng);
        v[static_cast<std::size_t>(x + 4 * (y + 4 * z))] = (mask >> c & 1) ? -m : m;
      }
      ScalarVolume vol{Vec3i::splat(4), v.data()};
      const Mesh mesh = mesh_volume(vol, with(Mesher::kMarchingCubes, 2));
      const MeshStats s = mesh_stats(mesh);
      ASSERT_TRUE(s.watertight()) << "mask " << mask << " trial " << trial << ": "
                                  << s.boundary_edges << " boundary, " << s.nonmanifold_edges
                                  << " non-manifold, " << s.misoriented_edges << " misoriented";
      ASSERT_GT(s.signed_volume_units3, 0) << "mask " << mask;
    }
}

// Random lattices are full of ambiguous faces and interior configurations: marching cubes gives a
// closed oriented manifold, surface nets a closed surface, and both the same triangles for every
// chunk edge and thread count.
TEST(Mesh, RandomFieldsAreWatertightAndIndependentOfChunksAndThreads) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1, 1);
  const int n = 27;
  std::vector<float> v(static_cast<std::size_t>(n) * n * n);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const bool border = x == 0 || y == 0 || z == 0 || x == n - 1 || y == n - 1 || z == n - 1;
        v[static_cast<std::size_t>(x + n * (y + n * z))] =
            border ? 1.0f : u(rng);  // closed inside the lattice
      }
  ScalarVolume vol{Vec3i::splat(n), v.data()};
  for (Mesher m : kMeshers) {
    SCOPED_TRACE(mesher_name(m));
    const Mesh reference = mesh_volume(vol, with(m, 256));  // one chunk
    const MeshStats s = mesh_stats(reference);
    // Surface nets joins every sheet crossing a cell into its one vertex, so where the surface
    // pinches within a cell an edge gets four triangles (Gibson's nets are closed, not manifold);
    // marching cubes keeps the sheets apart.
    auto closed = [&](const MeshStats& st) {
      return m == Mesher::kMarchingCubes ? st.watertight()
                                         : st.boundary_edges == 0 && st.degenerate_triangles == 0;
    };
    EXPECT_TRUE(closed(s)) << s.boundary_edges << " boundary, " << s.nonmanifold_edges
                           << " non-manifold, " << s.misoriented_edges << " misoriented";
    if (m != Mesher::kMarchingCubes) {
      EXPECT_GT(s.nonmanifold_edges, 0u);  // so this lattice does pinch
    }
    const auto expected = triangle_set(reference);
    for (int edge : {2, 3, 5, 8, 16, 25}) {
      for (int threads : {1, 2}) {
        ThreadLimit limit(threads);
        const Mesh mesh = mesh_volume(vol, with(m, edge));
        EXPECT_EQ(mesh.vertex_count(), reference.vertex_count()) << "chunk edge " << edge;
        EXPECT_TRUE(triangle_set(mesh) == expected)
            << "chunk edge " << edge << ", " << threads << " threads";
        EXPECT_TRUE(closed(mesh_stats(mesh))) << "chunk edge " << edge;
        // A whole volume is meshed in Flying Edges' passes (flying_edges.h); the chunked driver
        // MeshChunks keeps must give the same triangles.
        const Mesh chunked = MeshChunks(vol, with(m, edge)).merged();
        EXPECT_EQ(chunked.vertex_count(), reference.vertex_count()) << "chunk edge " << edge;
        EXPECT_TRUE(triangle_set(chunked) == expected)
            << "chunked driver, chunk edge " << edge << ", " << threads << " threads";
      }
    }
  }
}

// The same with the surface running out of the lattice's faces (open borders, the upper face's
// ownership rule): still the same triangles for every chunk edge and thread count.
TEST(Mesh, OpenSurfacesAreIndependentOfChunksAndThreads) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<float> u(-1, 1);
  const int n = 23;
  std::vector<float> v(static_cast<std::size_t>(n) * n * n);
  for (float& x : v) x = u(rng);
  ScalarVolume vol{Vec3i::splat(n), v.data()};
  for (Mesher m : kMeshers) {
    SCOPED_TRACE(mesher_name(m));
    const Mesh reference = mesh_volume(vol, with(m, 256));
    EXPECT_GT(mesh_stats(reference).boundary_edges, 0u);  // the surface does leave the lattice
    const auto expected = triangle_set(reference);
    for (int edge : {2, 3, 7, 11, 22})
      for (int threads : {1, 2}) {
        ThreadLimit limit(threads);
        const Mesh mesh = mesh_volume(vol, with(m, edge));
        EXPECT_EQ(mesh.vertex_count(), reference.vertex_count()) << "chunk edge " << edge;
        EXPECT_TRUE(triangle_set(mesh) == expected)
            << "chunk edge " << edge << ", " << threads << " threads";
        const Mesh chunked = MeshChunks(vol, with(m, edge)).merged();
        EXPECT_EQ(chunked.vertex_count(), reference.vertex_count()) << "chunk edge " << edge;
        EXPECT_TRUE(triangle_set(chunked) == expected)
            << "chunked driver, chunk edge " << edge << ", " << threads << " threads";
      }
  }
}

// The whole-volume passes work on rows of 64-sample words: lattices of 2 samples on an axis, rows
// just short of, at and past a word (63, 64, 65, 129 samples), inside-above densities and surfaces
// leaving the lattice give the chunked driver's triangles, for every mesher.
TEST(Mesh, WholeVolumePassesMatchTheChunkedDriverAtWordAndLatticeEdges) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(-1, 1);
  const Vec3i sizes[] = {{2, 2, 2},  {2, 5, 3},   {5, 2, 2},  {63, 3, 4}, {64, 4, 3},
                         {65, 3, 3}, {129, 3, 2}, {3, 66, 2}, {2, 3, 70}};
  for (const Vec3i n : sizes)
    for (bool steps : {false, true}) {
      // Smooth noise, or values of -1, 0 and 1: samples exactly at iso (crossings at an edge's end,
      // ties in the asymptotic decider, normals of no direction).
      std::vector<float> v(static_cast<std::size_t>(n.x) * n.y * n.z);
      for (float& x : v) x = steps ? std::round(u(rng) * 1.4f) : u(rng);
      // An anisotropic spacing and an origin away from zero, where the arithmetic is not exact.
      ScalarVolume vol{n, v.data()};
      vol.spacing_units = {0.5, 0.75, 1.3};
      vol.origin_units = {-3.1, 2.0, 0.7};
      for (Mesher m : kMeshers)
        for (bool above : {false, true}) {
          SCOPED_TRACE(std::string(mesher_name(m)) + " " + std::to_string(n.x) + "x" +
                       std::to_string(n.y) + "x" + std::to_string(n.z) + (above ? " above" : "") +
                       (steps ? " steps" : ""));
          MeshOptions o = with(m, 3);
          o.inside_above = above;
          const Mesh whole = mesh_volume(vol, o);
          const Mesh chunked = MeshChunks(vol, o).merged();
          EXPECT_EQ(whole.vertex_count(), chunked.vertex_count());
          // Positions and normals, bit for bit.
          EXPECT_TRUE(test::corner_triangles(whole) == test::corner_triangles(chunked));
          std::vector<bool> used(whole.vertex_count());
          for (std::uint32_t i : whole.indices) {
            ASSERT_LT(i, whole.vertex_count());
            used[i] = true;
          }
          EXPECT_EQ(std::count(used.begin(), used.end(), false), 0) << "unreferenced vertices";
        }
    }
  // Balls in air across a row's two words: most rows are quiet (they and their neighbours in y
  // and z all outside, or all inside for inside above), and the passes skip them.
  {
    const Vec3i n{70, 20, 18};
    std::vector<float> v(static_cast<std::size_t>(n.x) * n.y * n.z);
    for (int z = 0; z < n.z; ++z)
      for (int y = 0; y < n.y; ++y)
        for (int x = 0; x < n.x; ++x)
          v[static_cast<std::size_t>(x + n.x * (y + n.y * z))] =
              static_cast<float>(std::min(std::hypot(x - 20.3, y - 9.2, z - 8.6) - 6.1,
                                          std::hypot(x - 60.1, y - 12.7, z - 10.4) - 3.3));
    const ScalarVolume vol{n, v.data()};
    for (Mesher m : kMeshers)
      for (bool above : {false, true}) {
        SCOPED_TRACE(std::string(mesher_name(m)) + " balls" + (above ? " above" : ""));
        MeshOptions o = with(m, 3);
        o.inside_above = above;
        const Mesh whole = mesh_volume(vol, o);
        ASSERT_GT(whole.triangle_count(), 500u);
        EXPECT_TRUE(test::corner_triangles(whole) ==
                    test::corner_triangles(MeshChunks(vol, o).merged()));
      }
  }
  // A NaN in a row's second word is found by the vectorised scan and named.
  std::vector<float> v(70 * 3 * 3, 1.0f);
  v[66 + 70 * (1 + 3 * 2)] = std::numeric_limits<float>::quiet_NaN();
  try {
    mesh_volume({{70, 3, 3}, v.data()}, {});
    ADD_FAILURE() << "a NaN sample was meshed";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("sample (66, 1, 2) is NaN"), std::string::npos)
        << e.what();
  }
}

TEST(Mesh, InsideAboveIsTheMirroredConvention) {
  Sampled s(24, 1, [](Vec3d p) { return sdf::sphere(p, 7); });
  std::vector<float> density(s.values.size());
  for (std::size_t i = 0; i < density.size(); ++i) density[i] = 5.0f - s.values[i];  // > 5 inside
  ScalarVolume d = s.volume;
  d.values = density.data();
  for (Mesher m : kMeshers) {
    MeshOptions o = with(m);
    const Mesh below = mesh_volume(s.volume, o);
    o.iso = 5;
    o.inside_above = true;
    const Mesh above = mesh_volume(d, o);
    ASSERT_EQ(below.triangle_count(), above.triangle_count());
    EXPECT_GT(mesh_stats(above).signed_volume_units3, 0);
    EXPECT_NEAR(mesh_stats(above).signed_volume_units3, mesh_stats(below).signed_volume_units3,
                1e-3);
  }
}

// A World: the surface runs halfway between solid and air voxel centres whatever the bounds, with
// each vertex coloured by the material of the solid voxel it came from.
TEST(Mesh, WorldsAreMeshedThroughTheirSignedFieldWithPaletteColours) {
  World w(8, Box3i::from_size({10, 10, 10}));  // content touching the bounds: still closed
  w.voxels.fill(Box3i{{0, 0, 0}, {5, 10, 10}}, 1);
  w.voxels.fill(Box3i{{5, 0, 0}, {10, 10, 10}}, 2);
  for (Mesher m : kMeshers) {
    SCOPED_TRACE(mesher_name(m));
    const Mesh mesh = mesh_world(w, with(m, 4));
    expect_closed_manifold(mesh, 2, "two-material slab");
    EXPECT_NEAR(mesh_stats(mesh).signed_volume_units3, 1000, 60);  // bevelled edges and corners
    ASSERT_EQ(mesh.colors.size(), mesh.vertex_count());
    for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
      const Rgba c = w.palette[mesh.positions[i][0] < 5 ? 1 : 2];
      if (std::abs(mesh.positions[i][0] - 5) < 0.6f) continue;  // vertices on the material border
      EXPECT_EQ(mesh.colors[i], (std::array<std::uint8_t, 3>{c.r, c.g, c.b})) << "vertex " << i;
    }
  }
  EXPECT_EQ(mesh_world(World(16), with(Mesher::kMarchingCubes)).triangle_count(), 0u);
}

TEST(Mesh, BadRequestsAreRefusedClearly) {
  std::vector<float> v(8, 1.0f);
  ScalarVolume vol{Vec3i::splat(2), v.data()};
  MeshOptions o;
  EXPECT_EQ(mesh_volume(vol, o).triangle_count(), 0u);  // no surface: an empty mesh
  v[3] = std::numeric_limits<float>::quiet_NaN();
  try {
    mesh_volume(vol, o);
    FAIL() << "NaN accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("(1, 1, 0) is NaN"), std::string::npos) << e.what();
  }
  v[3] = 1;
  o.chunk_edge = 1;
  EXPECT_THROW(mesh_volume(vol, o), InvalidArgument);
  o.chunk_edge = 32;
  vol.spacing_units = {1, 0, 1};
  EXPECT_THROW(mesh_volume(vol, o), InvalidArgument);
  vol.spacing_units = {1, 1, 1};
  vol.size = {2, 1, 4};
  EXPECT_THROW(mesh_volume(vol, o), InvalidArgument);
  EXPECT_THROW(parse_mesher("dc2"), InvalidArgument);
  vol.size = Vec3i::splat(2);
  v[5] = std::numeric_limits<float>::infinity();
  try {
    mesh_volume(vol, o);
    FAIL() << "infinity accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("(1, 0, 1) is infinite"), std::string::npos) << e.what();
  }
  v[5] = 1;
  for (double bad : {-1.0, 0.0, std::numeric_limits<double>::infinity(),
                     std::numeric_limits<double>::quiet_NaN(), 1e-300, 1e300}) {
    vol.spacing_units = {1, bad, 1};
    EXPECT_THROW(mesh_volume(vol, o), InvalidArgument) << "spacing " << bad;
  }
  vol.spacing_units = {1, 1, 1};
  vol.origin_units = {0, std::numeric_limits<double>::quiet_NaN(), 0};
  EXPECT_THROW(mesh_volume(vol, o), InvalidArgument);
  vol.origin_units = {0, 0, 0};
  for (double bad : {std::numeric_limits<double>::infinity(), 1e300}) {
    o.iso = bad;
    EXPECT_THROW(mesh_volume(vol, o), InvalidArgument) << "iso " << bad;
  }
  o.iso = 0;
  o.chunk_edge = 257;
  EXPECT_THROW(mesh_volume(vol, o), InvalidArgument);
  // Millions of chunks of 2 cells for a volume that size: the chunked driver's bookkeeping alone
  // is refused; so is the whole-volume passes' (half a terabyte of inside bits), before a sample
  // is read.
  std::vector<float> big(1);
  ScalarVolume huge{Vec3i::splat(1 << 14), big.data()};
  o.chunk_edge = 2;
  EXPECT_THROW(MeshChunks(huge, o), ResourceLimitError);
  EXPECT_THROW(mesh_volume(huge, o), ResourceLimitError);
  Mesh bad_indices;
  bad_indices.positions.resize(2);
  bad_indices.normals.resize(2);
  bad_indices.indices = {0, 1, 2};
  EXPECT_THROW(mesh_stats(bad_indices), InvalidArgument);
  EXPECT_EQ(parse_mesher("surface-nets"), Mesher::kSurfaceNets);
}

// Dual contouring keeps a box's corners and edges where marching cubes bevels them: on a box not
// aligned with the lattice (spacing 0.5), its vertices sit on the box and nearer its corners. From
// samples alone a crease cannot be exact: crossings near it are interpolated across the kink of
// the distance field, so corners come within half a sample (marching cubes: up to 1.3 samples).
TEST(Mesh, DualContouringKeepsSharpCorners) {
  const Vec3d half{5.3, 4.15, 3.35}, centre{0.11, -0.07, 0.13};
  Sampled box(32, 0.5, [&](Vec3d p) { return sdf::box(p - centre, half); });
  auto corner_errors = [&](const Mesh& mesh) {
    double worst = 0, sum = 0;
    for (int c = 0; c < 8; ++c) {
      const Vec3d corner{centre.x + ((c & 1) ? half.x : -half.x),
                         centre.y + ((c >> 1 & 1) ? half.y : -half.y),
                         centre.z + ((c >> 2 & 1) ? half.z : -half.z)};
      double best = 1e9;
      for (const auto& p : mesh.positions) best = std::min(best, (at(p) - corner).length());
      worst = std::max(worst, best);
      sum += best;
    }
    return std::pair{worst, sum / 8};
  };
  const Mesh dc = mesh_volume(box.volume, with(Mesher::kDualContouring, 8));
  const Mesh mc = mesh_volume(box.volume, with(Mesher::kMarchingCubes, 8));
  expect_closed_manifold(dc, 2, "box, dual contouring");
  const double volume = 8 * half.x * half.y * half.z;
  EXPECT_NEAR(mesh_stats(dc).signed_volume_units3, volume, 0.005 * volume);
  EXPECT_LT(std::abs(mesh_stats(dc).signed_volume_units3 - volume),
            std::abs(mesh_stats(mc).signed_volume_units3 - volume));
  const auto [dc_worst, dc_mean] = corner_errors(dc);
  const auto [mc_worst, mc_mean] = corner_errors(mc);
  EXPECT_LT(dc_worst, 0.25) << "a corner is farther than half a sample from every vertex";
  EXPECT_LT(dc_mean, 0.4 * mc_mean)
      << "dual contouring " << dc_mean << ", marching cubes " << mc_mean;
  double off = 0;
  for (const auto& p : dc.positions) off = std::max(off, std::abs(sdf::box(at(p) - centre, half)));
  EXPECT_LT(off, 0.03);  // every vertex within 6 % of a sample of the box
}
