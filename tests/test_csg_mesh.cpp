// Meshes of CSG models: dual contouring with the model's own gradient keeps a box's corners and a
// gear's slots sharp, closes the surface, puts vertices on it, paints them, and gives the same
// triangles for every chunk edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "csg_examples.h"
#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"
#include "voxfield/csg_mesh.h"

namespace voxfield {
namespace {

csg::Model parse(const std::string& text) {
  return csg::parse_model(text, "test.sdf");
}

// Triangles as sorted position triples, so meshes compare whatever their vertex order.
std::vector<std::array<float, 9>> triangles(const Mesh& m) {
  std::vector<std::array<float, 9>> out;
  for (std::size_t t = 0; t < m.triangle_count(); ++t) {
    std::array<std::array<float, 3>, 3> v;
    for (int k = 0; k < 3; ++k)
      v[static_cast<std::size_t>(k)] = m.positions[m.indices[3 * t + static_cast<std::size_t>(k)]];
    std::rotate(v.begin(), std::min_element(v.begin(), v.end()), v.end());  // keep the winding
    out.push_back(
        {v[0][0], v[0][1], v[0][2], v[1][0], v[1][1], v[1][2], v[2][0], v[2][1], v[2][2]});
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(CsgMesh, DualContouringKeepsABoxsCornersAndEdgesExactly) {
  // Extents off the lattice: every corner and edge falls inside a cell, whose crossings carry the
  // faces' exact normals, so the tangent planes meet exactly there.
  const csg::Model m = parse("(move 0.11 -0.07 0.05 (box 2.1 3.3 4.45))");
  CsgMeshOptions o;
  o.voxel_size = 0.37;
  o.mesh.algorithm = Mesher::kDualContouring;
  const Mesh mesh = mesh_csg(m, o);
  const MeshStats st = mesh_stats(mesh);
  EXPECT_TRUE(st.watertight());
  EXPECT_EQ(st.euler_characteristic, 2);
  EXPECT_NEAR(st.signed_volume_units3, 2.1 * 3.3 * 4.45, 1e-3);
  for (int c = 0; c < 8; ++c) {
    const std::array<double, 3> corner{0.11 + (c & 1 ? 1.05 : -1.05),
                                       -0.07 + (c & 2 ? 1.65 : -1.65),
                                       0.05 + (c & 4 ? 2.225 : -2.225)};
    double best = 1e9;
    for (const auto& p : mesh.positions)
      best = std::min(best, std::hypot(p[0] - corner[0], p[1] - corner[1], p[2] - corner[2]));
    EXPECT_LT(best, 1e-5) << "corner " << c;
  }
  const csg::Tape tape = csg::compile_tape(m);
  for (const auto& p : mesh.positions)
    ASSERT_LT(std::abs(csg::evaluate(tape, {p[0], p[1], p[2]})), 1e-5);
  // Rotated, corners can fall in cells whose samples are all outside (a feature under a cell):
  // the mesh still closes and its vertices still lie on the faces' planes.
  const csg::Model r = parse("(rotate 20 1 2 3 (box 2 3 4))");
  const Mesh rm = mesh_csg(r, o);
  EXPECT_TRUE(mesh_stats(rm).watertight());
  EXPECT_NEAR(mesh_stats(rm).signed_volume_units3, 24, 24 * 0.02);
  const csg::Tape rt = csg::compile_tape(r);
  for (const auto& p : rm.positions)
    ASSERT_LT(std::abs(csg::evaluate(rt, {p[0], p[1], p[2]})), 0.1 * o.voxel_size);
}

TEST(CsgMesh, GearMeshesCloseLieOnTheSurfaceAndAreSeamless) {
  const csg::Model gear = test::csg_example("gear.sdf");
  const csg::Tape tape = csg::compile_tape(gear);
  for (Mesher algorithm : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
    CsgMeshOptions o;
    o.voxel_size = 0.2;
    o.mesh.algorithm = algorithm;
    const Mesh mesh = mesh_csg(gear, o);
    const MeshStats st = mesh_stats(mesh);
    EXPECT_TRUE(st.watertight()) << mesher_name(algorithm);
    // The gear: a disc of radius 10 and height 3 minus a bore and sixteen slots.
    const double disc = 3.14159265358979 * 100 * 3, bore = 3.14159265358979 * 6.25 * 3;
    EXPECT_GT(st.signed_volume_units3, 0.75 * (disc - bore)) << mesher_name(algorithm);
    EXPECT_LT(st.signed_volume_units3, disc - bore) << mesher_name(algorithm);
    // Crossings are found on the model itself: marching cubes' vertices lie on the surface;
    // surface nets' at the mean of a cell's crossings; dual contouring's on the tangent planes.
    const double tolerance =
        algorithm == Mesher::kSurfaceNets ? 0.87 * o.voxel_size  // in the cell
        : algorithm == Mesher::kMarchingCubes
            ? 1e-6
            : 0.15 * o.voxel_size;  // clamped into their cells where features are finer
    for (const auto& p : mesh.positions)
      ASSERT_LT(std::abs(csg::evaluate(tape, {p[0], p[1], p[2]})), tolerance)
          << mesher_name(algorithm);
    const Rgba brass = gear.palette[csg::material_at(gear, {9, 0, 0})];
    ASSERT_FALSE(mesh.colors.empty());
    EXPECT_EQ(mesh.colors[0], (std::array<std::uint8_t, 3>{brass.r, brass.g, brass.b}));
    o.mesh.chunk_edge = 5;
    EXPECT_EQ(triangles(mesh_csg(gear, o)), triangles(mesh)) << mesher_name(algorithm);
  }
}

TEST(CsgMesh, RefusesUnboundedModelsWithoutABox) {
  CsgMeshOptions o;
  EXPECT_THROW((void)mesh_csg(parse("(plane 0 0 1 0)"), o), InvalidArgument);
  o.box = csg::Bounds{{-1, -1, -1}, {1, 1, 1}};
  o.voxel_size = 0.25;
  const Mesh m = mesh_csg(parse("(plane 0 0 1 0)"), o);
  EXPECT_GT(m.triangle_count(), 0u);
}

}  // namespace
}  // namespace voxfield
