// Triangle meshes in: the readers (OBJ, PLY ASCII/binary, STL ASCII/binary, OFF) against meshes
// built here and voxfield's own writers, their refusals with the offending byte; the winding
// number against its exact sum and against shapes with known insides; voxelisation and signed
// distance fields against brute force (every triangle's exact distance, the exact winding number)
// and against an analytic cube.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>

#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_read.h"
#include "voxfield/mesh_voxelize.h"
#include "voxfield/parallel.h"

namespace voxfield {
namespace {

using P = std::array<double, 3>;

std::span<const std::uint8_t> bytes_of(const std::string& s) {
  return {reinterpret_cast<const std::uint8_t*>(s.data()), s.size()};
}

// An icosahedron subdivided `levels` times, its vertices pushed onto the sphere of `radius` about
// `centre`; counter-clockwise from outside.
TriangleMesh icosphere(int levels, double radius, P centre = {0, 0, 0}) {
  const double t = (1 + std::sqrt(5.0)) / 2;
  TriangleMesh m;
  m.positions = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                 {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
    const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      P p;
      for (int k = 0; k < 3; ++k) p[k] = (m.positions[a][k] + m.positions[b][k]) / 2;
      m.positions.push_back(p);
      return mid[key] = static_cast<std::uint32_t>(m.positions.size() - 1);
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& f : m.triangles) {
      const std::uint32_t a = midpoint(f[0], f[1]), b = midpoint(f[1], f[2]),
                          c = midpoint(f[2], f[0]);
      next.insert(next.end(), {{f[0], a, c}, {f[1], b, a}, {f[2], c, b}, {a, b, c}});
    }
    m.triangles = std::move(next);
  }
  for (P& p : m.positions) {
    const double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int k = 0; k < 3; ++k) p[k] = centre[k] + p[k] / len * radius;
  }
  return m;
}

// The box [lo, hi] as 12 triangles, outward.
TriangleMesh box_mesh(P lo, P hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back({i & 1 ? hi[0] : lo[0], i & 2 ? hi[1] : lo[1], i & 4 ? hi[2] : lo[2]});
  m.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                 {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return m;
}

// The exact signed distance to the box [lo, hi].
double box_sdf(P p, P lo, P hi) {
  double outside2 = 0, inside = -HUGE_VAL;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max(lo[k] - p[k], p[k] - hi[k]);
    if (d > 0) outside2 += d * d;
    inside = std::max(inside, d);
  }
  return outside2 > 0 ? std::sqrt(outside2) : inside;
}

// The brute-force oracle: the smallest exact distance to any triangle, signed by the exact
// winding number.
double brute_sdf(const TriangleMesh& m, const WindingNumber& w, P p) {
  double best = HUGE_VAL;
  for (const auto& t : m.triangles)
    best = std::min(
        best, point_triangle_distance(p, m.positions[t[0]], m.positions[t[1]], m.positions[t[2]]));
  return w.exact(p) >= 0.5 ? -best : best;
}

P centre_of(Vec3i v, double size) {
  return {(v.x + 0.5) * size, (v.y + 0.5) * size, (v.z + 0.5) * size};
}

TEST(MeshInput, PointTriangleDistanceMatchesDenseSamplingOfTheTriangle) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2, 2);
  for (int round = 0; round < 300; ++round) {
    P a{u(rng), u(rng), u(rng)}, b{u(rng), u(rng), u(rng)}, c{u(rng), u(rng), u(rng)},
        p{u(rng), u(rng), u(rng)};
    if (round % 10 == 0) c = b;  // degenerate: a segment
    double sampled = HUGE_VAL;
    const int n = 200;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j) {
        const double s = double(i) / n, t = double(j) / n;
        P q;
        for (int k = 0; k < 3; ++k) q[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
        sampled = std::min(sampled, std::hypot(p[0] - q[0], p[1] - q[1], p[2] - q[2]));
      }
    const double exact = point_triangle_distance(p, a, b, c);
    EXPECT_LE(exact, sampled + 1e-12) << round;  // never above a point of the triangle
    EXPECT_GE(exact, sampled - 0.03) << round;   // the grid's spacing bounds how far it can miss
  }
}

TEST(MeshInput, WindingNumbersOfClosedAndHoledSpheres) {
  const TriangleMesh sphere = icosphere(3, 1.0);
  const WindingNumber w(sphere), fine(sphere, 8.0);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-3, 3);
  double worst = 0, worst_fine = 0;
  for (int i = 0; i < 2000; ++i) {
    const P p{u(rng), u(rng), u(rng)};
    const double r = std::hypot(p[0], p[1], p[2]);
    const double exact = w.exact(p);
    worst = std::max(worst, std::abs(exact - w(p)));
    worst_fine = std::max(worst_fine, std::abs(exact - fine(p)));
    if (r < 0.95) {
      EXPECT_NEAR(exact, 1.0, 1e-9) << r;
    } else if (r > 1.0) {
      EXPECT_NEAR(exact, 0.0, 1e-9) << r;
    }
    EXPECT_EQ(w.inside(p), exact >= 0.5) << r;
  }
  // The far-field expansion's error: below 0.07 of a turn at the paper's accuracy of 2 (the margin
  // inside() asks again within is 0.25), and it shrinks as the accuracy grows.
  EXPECT_LT(worst, 0.07);
  EXPECT_LT(worst_fine, 5e-3);
  // A sphere with its top cap cut away: the centre still sees most of the surface; points in the
  // hole's opening are decided as the exact sum decides them.
  TriangleMesh holed = sphere;
  std::erase_if(holed.triangles, [&](const auto& t) {
    return holed.positions[t[0]][2] > 0.7 && holed.positions[t[1]][2] > 0.7 &&
           holed.positions[t[2]][2] > 0.7;
  });
  ASSERT_LT(holed.triangles.size(), sphere.triangles.size());
  const WindingNumber wh(holed);
  const double centre = wh.exact({0, 0, 0});
  EXPECT_GT(centre, 0.8);
  EXPECT_LT(centre, 0.99);
  EXPECT_NEAR(wh({0, 0, 0}), centre, 0.07);
  int near_half = 0;
  std::uniform_real_distribution<double> cap(-0.8, 0.8), height(0.5, 1.2);
  for (int i = 0; i < 3000; ++i) {
    const P p{cap(rng), cap(rng), height(rng)};
    const double exact = wh.exact(p);
    if (std::abs(exact - 0.5) < 1e-2) continue;
    near_half += std::abs(exact - 0.5) < 0.25;
    ASSERT_EQ(wh.inside(p), exact >= 0.5) << p[0] << "," << p[1] << "," << p[2] << ": " << exact;
  }
  EXPECT_GT(near_half, 100);  // the refinement was exercised
}

TEST(MeshInput, VoxelisationIsTheExactWindingNumberAtCentres) {
  const TriangleMesh sphere = icosphere(2, 3.3, {0.2, -0.4, 0.1});
  MeshVoxelOptions o;
  o.voxel_size = 0.5;
  const World world = voxelize_mesh(sphere, o);
  const Box3i box = *world.voxels.bounds();
  EXPECT_EQ(box, mesh_voxel_box(sphere, o));
  const WindingNumber w(sphere);
  std::int64_t solid = 0, checked = 0;
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x) {
        const double exact = w.exact(centre_of({x, y, z}, 0.5));
        if (std::abs(exact - 0.5) < 1e-2)
          continue;  // within the hierarchy's error of the threshold
        ++checked;
        const bool want = exact >= 0.5;
        solid += want;
        ASSERT_EQ(world.voxels.get({x, y, z}) != 0, want) << x << "," << y << "," << z;
      }
  EXPECT_GT(checked, 0.99 * static_cast<double>(box.volume()));
  // The ball's volume over a voxel's: the solid count within the surface's voxels of it.
  const double ball = 4.0 / 3.0 * 3.14159265358979 * 3.3 * 3.3 * 3.3 / 0.125;
  EXPECT_NEAR(static_cast<double>(solid), ball, 0.08 * ball);
}

TEST(MeshInput, AHoledMeshVoxelisesLikeItsClosedSelf) {
  const TriangleMesh sphere = icosphere(3, 5.0);
  TriangleMesh holed = sphere;
  std::mt19937 rng(11);
  // Knock out 3 % of the triangles at random: a scan's drop-outs.
  std::erase_if(holed.triangles, [&](const auto&) { return rng() % 100 < 3; });
  MeshVoxelOptions o;
  o.voxel_size = 0.5;
  const World closed = voxelize_mesh(sphere, o), open = voxelize_mesh(holed, o);
  std::int64_t differ = 0;
  const Box3i box = *closed.voxels.bounds();
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x)
        differ += (closed.voxels.get({x, y, z}) != 0) != (open.voxels.get({x, y, z}) != 0);
  EXPECT_GT(closed.solid_count(), 3000);
  EXPECT_LT(differ, closed.solid_count() / 100) << "only voxels at the holes' rims may differ";
}

TEST(MeshInput, SoupsAreJudgedByTheirWindingNumberEverywhere) {
  // An open square sheet laid twice (a soup: the doubled sheet winds a full turn just behind it,
  // outside the mesh's flat bounding box), and a closed cube beside it.
  TriangleMesh soup;
  soup.positions = {{0, 0, 1}, {3, 0, 1}, {3, 3, 1}, {0, 3, 1}};
  soup.triangles = {{0, 1, 2}, {0, 2, 3}, {0, 1, 2}, {0, 2, 3}};
  const TriangleMesh cube = box_mesh({4.2, 0.3, 0.1}, {6.1, 2.2, 1.9});
  for (const auto& t : cube.triangles) soup.triangles.push_back({t[0] + 4, t[1] + 4, t[2] + 4});
  soup.positions.insert(soup.positions.end(), cube.positions.begin(), cube.positions.end());
  MeshVoxelOptions o;
  o.voxel_size = 0.25;
  const World world = voxelize_mesh(soup, o);
  MeshDistanceOptions d;
  d.voxel_size = 0.25;
  const MeshDistanceField field = mesh_distance_field(soup, d);
  const WindingNumber w(soup);
  const Box3i box = *world.voxels.bounds();
  ASSERT_EQ(box, field.box);
  std::int64_t wound = 0;
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x) {
        const double exact = w.exact(centre_of({x, y, z}, 0.25));
        if (std::abs(exact - 0.5) < 0.05) continue;
        wound += exact >= 0.5;
        ASSERT_EQ(world.voxels.get({x, y, z}) != 0, exact >= 0.5)
            << x << "," << y << "," << z << ": " << exact;
        ASSERT_EQ(field.at({x, y, z}) < 0, exact >= 0.5)
            << x << "," << y << "," << z << ": " << exact;
      }
  EXPECT_GT(wound, 100);
  // A flat mesh with no padding still gets a box, one voxel thick.
  TriangleMesh flat = soup;
  flat.triangles.resize(2);
  o.padding_voxels = 0;
  EXPECT_EQ(mesh_voxel_box(flat, o).size().z, 1);
  EXPECT_EQ(voxelize_mesh(flat, o).solid_count(), 0);
}

TEST(MeshInput, CubeFieldIsTheAnalyticBoxField) {
  const P lo{-1.3, 0.45, 2.1}, hi{2.2, 3.05, 3.9};
  const TriangleMesh cube = box_mesh(lo, hi);
  MeshDistanceOptions o;
  o.voxel_size = 0.25;
  o.padding_voxels = 12;  // well beyond the band: the transform's part is checked too
  const MeshDistanceField f = mesh_distance_field(cube, o);
  ASSERT_EQ(f.values.size(), static_cast<std::size_t>(f.box.volume()));
  EXPECT_LT(f.band_voxels, f.box.volume());
  double worst = 0;
  for (int z = f.box.begin.z; z < f.box.end.z; ++z)
    for (int y = f.box.begin.y; y < f.box.end.y; ++y)
      for (int x = f.box.begin.x; x < f.box.end.x; ++x)
        worst = std::max(worst,
                         std::abs(f.at({x, y, z}) - box_sdf(centre_of({x, y, z}, 0.25), lo, hi)));
  EXPECT_LT(worst, 2e-6);  // float rounding only
}

TEST(MeshInput, ClampedFieldsAreTheFullFieldClamped) {
  const TriangleMesh sphere = icosphere(2, 2.0, {0.3, 0.1, -0.2});
  MeshDistanceOptions o;
  o.voxel_size = 0.25;
  o.padding_voxels = 6;
  const MeshDistanceField full = mesh_distance_field(sphere, o);
  for (const double clamp : {0.1, 0.5, 0.75, 1.2}) {  // within the band (0.75) and beyond it
    o.max_distance = clamp;
    const MeshDistanceField f = mesh_distance_field(sphere, o);
    ASSERT_EQ(f.values.size(), full.values.size());
    for (std::size_t i = 0; i < f.values.size(); ++i)
      ASSERT_EQ(f.values[i],
                std::clamp(full.values[i], -static_cast<float>(clamp), static_cast<float>(clamp)))
          << clamp << " at " << i;
  }
}

TEST(MeshInput, FieldsMatchBruteForceAndDoNotDependOnThreads) {
  // A sphere, a holed sphere and two overlapping spheres (a soup, not a manifold).
  TriangleMesh two = icosphere(2, 2.0, {0, 0, 0});
  const TriangleMesh other = icosphere(2, 1.6, {1.5, 0.5, 0.2});
  for (const auto& t : other.triangles)
    two.triangles.push_back({t[0] + static_cast<std::uint32_t>(two.positions.size()),
                             t[1] + static_cast<std::uint32_t>(two.positions.size()),
                             t[2] + static_cast<std::uint32_t>(two.positions.size())});
  two.positions.insert(two.positions.end(), other.positions.begin(), other.positions.end());
  TriangleMesh holed = icosphere(2, 2.4);
  holed.triangles.erase(holed.triangles.begin(), holed.triangles.begin() + 12);
  for (const TriangleMesh* mesh : {&two, &holed}) {
    MeshDistanceOptions o;
    o.voxel_size = 0.3;
    o.padding_voxels = 8;
    const MeshDistanceField f = mesh_distance_field(*mesh, o);
    MeshDistanceField single;
    {
      ThreadLimit one(1);
      single = mesh_distance_field(*mesh, o);
    }
    EXPECT_EQ(std::memcmp(f.values.data(), single.values.data(), f.values.size() * sizeof(float)),
              0);
    const WindingNumber w(*mesh);
    double worst_band = 0, worst_far = 0, below = 0;
    for (int z = f.box.begin.z; z < f.box.end.z; ++z)
      for (int y = f.box.begin.y; y < f.box.end.y; ++y)
        for (int x = f.box.begin.x; x < f.box.end.x; ++x) {
          const P c = centre_of({x, y, z}, 0.3);
          const double want = brute_sdf(*mesh, w, c), got = f.at({x, y, z});
          if (std::abs(w.exact(c) - 0.5) < 1e-2) continue;  // the sign is the hierarchy's call
          const double err = std::abs(got - want);
          if (std::abs(want) <= o.band_voxels * o.voxel_size) {
            worst_band = std::max(worst_band, err);
          } else {
            worst_far = std::max(worst_far, err);
            below = std::max(below, std::abs(want) - std::abs(got));
          }
        }
    EXPECT_LT(worst_band, 1e-5);                // exact in the band
    EXPECT_LT(below, 1e-5);                     // never nearer than the true surface
    EXPECT_LT(worst_far, 0.05 * o.voxel_size);  // and close to it beyond the band
  }
}

TEST(MeshInput, ReadersAgreeOnTheSameMesh) {
  // Two quads and a triangle (a fan each) in every text format, with the extras real files carry.
  const std::string obj =
      "# exported\nmtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\nv 0 0 1 0.5 0.5 "
      "0.5\n"
      "vt 0 0\nvn 0 0 1\ns off\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -5//1 -4//1 -1//1\nl 1 2\n";
  const std::string off =
      "OFF\n# comment\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n4 0 1 2 3\n3 0 1 4 255 0 0\n";
  const std::string ply =
      "ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 5\nproperty float x\nproperty "
      "float y\n"
      "property float z\nproperty uchar red\nelement face 2\nproperty list uchar int "
      "vertex_indices\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
      "0 0 0 1\n1 0 0 2\n1 1 0 3\n0 1 0 4\n0 0 1 5\n4 0 1 2 3\n3 0 1 4\n0 1\n";
  const std::vector<std::array<std::uint32_t, 3>> want = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}};
  for (const auto& [text, format] :
       {std::pair{obj, MeshInputFormat::kObj}, std::pair{off, MeshInputFormat::kOff},
        std::pair{ply, MeshInputFormat::kPly}}) {
    const TriangleMesh m = parse_mesh(bytes_of(text), format, "test");
    ASSERT_EQ(m.positions.size(), 5u) << mesh_input_format_name(format);
    EXPECT_EQ(m.triangles, want) << mesh_input_format_name(format);
    EXPECT_EQ(m.positions[4], (P{0, 0, 1}));
  }
  // Binary PLY, both byte orders, with doubles and a ushort count.
  for (const bool big : {false, true}) {
    std::string b =
        std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
        " 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\n"
        "element face 1\nproperty list ushort uint vertex_indices\nend_header\n";
    const auto put = [&](const void* p, std::size_t n) {
      std::string raw(static_cast<const char*>(p), n);
      if (big) std::reverse(raw.begin(), raw.end());
      b += raw;
    };
    for (double v : {0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0, -2.25, 0.0}) put(&v, 8);
    const std::uint16_t n = 3;
    put(&n, 2);
    for (std::uint32_t i : {0u, 1u, 2u}) put(&i, 4);
    const TriangleMesh m = parse_mesh(bytes_of(b), MeshInputFormat::kPly, "test.ply");
    ASSERT_EQ(m.triangles.size(), 1u);
    EXPECT_EQ(m.positions[2], (P{0, -2.25, 0}));
  }
}

TEST(MeshInput, VoxfieldsOwnMeshFilesReadBack) {
  const TriangleMesh sphere = icosphere(2, 1.0, {0.5, 0.25, -1});
  Mesh out;
  for (const P& p : sphere.positions) {
    out.positions.push_back(
        {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])});
    out.normals.push_back({0, 0, 1});
  }
  for (const auto& t : sphere.triangles) out.indices.insert(out.indices.end(), t.begin(), t.end());
  for (const MeshFormat f : {MeshFormat::kPly, MeshFormat::kObj, MeshFormat::kStl}) {
    const auto bytes = encode_mesh(out, f);
    const MeshInputFormat in = f == MeshFormat::kPly   ? MeshInputFormat::kPly
                               : f == MeshFormat::kObj ? MeshInputFormat::kObj
                                                       : MeshInputFormat::kStl;
    const TriangleMesh back = parse_mesh(bytes, in, "back");
    ASSERT_EQ(back.triangles.size(), sphere.triangles.size()) << mesh_format_name(f);
    // STL repeats corners per facet; welded back they are the same vertices.
    EXPECT_EQ(back.positions.size(), sphere.positions.size()) << mesh_format_name(f);
    for (std::size_t t = 0; t < back.triangles.size(); ++t)
      for (int k = 0; k < 3; ++k)
        for (int a = 0; a < 3; ++a)
          ASSERT_EQ(static_cast<float>(back.positions[back.triangles[t][k]][a]),
                    out.positions[sphere.triangles[t][k]][a])
              << mesh_format_name(f);
  }
  // ASCII STL of one facet, and a binary STL whose header begins with "solid" (exporters do that).
  const TriangleMesh ascii = parse_mesh(
      bytes_of("solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
               "   vertex 0 1 0\n  endloop\n endfacet\nendsolid t\n"),
      MeshInputFormat::kStl, "a.stl");
  EXPECT_EQ(ascii.triangles.size(), 1u);
  auto binary = encode_mesh(out, MeshFormat::kStl);
  std::memcpy(binary.data(), "solid exported", 14);
  EXPECT_EQ(parse_mesh(binary, MeshInputFormat::kStl, "b.stl").triangles.size(),
            sphere.triangles.size());
}

TEST(MeshInput, MalformedFilesAreRefusedWithTheirOffset) {
  const auto refuses = [](const std::string& text, MeshInputFormat f, std::uint64_t offset,
                          const std::string& part) {
    try {
      parse_mesh(bytes_of(text), f, "bad.mesh");
      ADD_FAILURE() << "accepted: " << text.substr(0, 40);
    } catch (const FormatError& e) {
      EXPECT_EQ(e.offset(), offset) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.mesh"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
    }
  };
  refuses("v 0 0 0\nv 1 0 0\nf 1 2 3\n", MeshInputFormat::kObj, 22,
          "names vertex 3, but 2 vertices");
  refuses("v 0 0 0\nv 1 0 0\nf 1 2 -3\n", MeshInputFormat::kObj, 22, "names vertex -3, but 2");
  refuses("v 0 0 0\nv 1 0 nan\n", MeshInputFormat::kObj, 14, "not finite");
  refuses("v 0 0 0\nf 1 1\n", MeshInputFormat::kObj, 8, "at least 3");
  refuses("v 0 0 x\n", MeshInputFormat::kObj, 6, "expected a z coordinate");
  refuses("OFF\n1000000 1 0\n0 0 0\n", MeshInputFormat::kOff, 4, "do not fit");
  refuses("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", MeshInputFormat::kOff, 34,
          "names vertex 7, but 3");
  refuses("OFF BINARY\n", MeshInputFormat::kOff, 4, "binary OFF");
  refuses("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n0\n1\n2\n",
          MeshInputFormat::kPly, 0, "no face element");
  refuses("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n",
          MeshInputFormat::kPly, 21, "3 vertex elements cannot fit");
  refuses(
      "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
      "property float y\nproperty float z\nelement face 0\nproperty list uchar int vertex_indices\n"
      "end_header\n",
      MeshInputFormat::kPly, 36, "cannot fit");
  refuses(
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float "
      "z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n3 0 0 5\n",
      MeshInputFormat::kPly, 166, "names vertex 5");
  refuses("ply\nformat ascii 1.0\nelement vertex 1\n", MeshInputFormat::kPly, 38, "no end_header");
  refuses(std::string(90, 'x'), MeshInputFormat::kStl, 80, "not binary STL");
  refuses(
      "solid t\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n  endloop\n "
      "endfacet\nendsolid\n",
      MeshInputFormat::kStl, 9, "at least 3");
}

TEST(MeshInput, BadRequestsAreRefused) {
  const TriangleMesh sphere = icosphere(1, 1.0);
  MeshVoxelOptions o;
  o.voxel_size = 0;
  EXPECT_THROW(voxelize_mesh(sphere, o), InvalidArgument);
  o.voxel_size = 1e-9;  // 2e9 voxels along each axis
  EXPECT_THROW(voxelize_mesh(sphere, o), InvalidArgument);
  o.voxel_size = 1e-3;  // 2004^3 voxels: more than 32-bit voxel indices hold
  EXPECT_THROW(voxelize_mesh(sphere, o), InvalidArgument);
  o.voxel_size = 2.5e-3;  // 804^3 voxels: past a 1 GiB limit
  o.memory_limit_bytes = std::uint64_t{1} << 30;
  EXPECT_THROW(voxelize_mesh(sphere, o), ResourceLimitError);
  EXPECT_THROW(voxelize_mesh(TriangleMesh{}, MeshVoxelOptions{}), InvalidArgument);
  TriangleMesh broken = sphere;
  broken.triangles[3][1] = 9999;
  EXPECT_THROW(voxelize_mesh(broken, MeshVoxelOptions{}), InvalidArgument);
  MeshDistanceOptions d;
  d.band_voxels = 0.5;
  EXPECT_THROW(mesh_distance_field(sphere, d), InvalidArgument);
  EXPECT_THROW(read_mesh("/nonexistent/x.obj"), IoError);
  EXPECT_THROW(read_mesh("x.txt"), InvalidArgument);
}

}  // namespace
}  // namespace voxfield
