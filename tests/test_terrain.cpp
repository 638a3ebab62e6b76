// The terrain field (terrain.h) against its definition: every stored sample is the documented
// quantisation of the clamped value; a brush equals its formula applied to every sample (so its
// locality is checked, not assumed); meshes of the chunked field equal meshes of its decoded
// volume, and MeshChunks follows edits exactly; the quantisation's effect on vertices is measured
// against the analytic surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "error_text.h"
#include "mesh_compare.h"
#include "voxfield/error.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/primitives.h"
#include "voxfield/terrain.h"

namespace voxfield {
namespace terrain_test {  // named: unity builds merge the test files

using test::error_of;

constexpr TerrainStorage kStorages[] = {TerrainStorage::kI8, TerrainStorage::kI16,
                                        TerrainStorage::kF32};

// The documented encoding, written out again: clamp to ±clamp, then code = round(v / step) (half
// away from zero) decoded as code * step in float, or the clamped float itself for f32.
float quantised(TerrainStorage s, double clamp, double v) {
  const double c = std::clamp(v, -clamp, clamp);
  if (s == TerrainStorage::kF32) return static_cast<float>(c);
  const double step = clamp / (s == TerrainStorage::kI8 ? 127 : 32767);
  return static_cast<float>(std::round(c / step) * step);
}

// The polynomial smooth minimum, from its formula.
double smin(double a, double b, double k) {
  if (k == 0) return std::min(a, b);
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k / 4;
}

double brush_sdf(const TerrainBrush& b, Vec3d p) {
  if (b.shape == TerrainBrush::Shape::kSphere)
    return sdf::sphere(p - b.centre_units, b.radius_units);
  if (b.shape == TerrainBrush::Shape::kBox)
    return sdf::box(p - b.centre_units, b.half_extents_units);
  return sdf::capsule(p, b.centre_units, b.end_units, b.radius_units);
}

TerrainOptions options_of(TerrainStorage s, Vec3i n, int chunk_edge = 8) {
  TerrainOptions o;
  o.samples = n;
  o.storage = s;
  o.chunk_edge = chunk_edge;
  o.origin_units = {-1.5, 2.0, 0.25};
  o.spacing_units = 0.5;
  return o;
}

Vec3d position(const TerrainOptions& o, int x, int y, int z) {
  return {o.origin_units[0] + x * o.spacing_units, o.origin_units[1] + y * o.spacing_units,
          o.origin_units[2] + z * o.spacing_units};
}

template <class F>
void for_each_sample(Vec3i n, F&& f) {
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) f(Vec3i{x, y, z});
}

// A rolling ground: the height z0 + 2 sin(x / 3) cos(y / 4) (a bound of the distance, as terrain
// generators give).
double ground(const Vec3d& p) {
  return p.z - (7 + 2 * std::sin(p.x / 3) * std::cos(p.y / 4));
}

TEST(Terrain, SamplesAreTheDocumentedQuantisationOfTheClampedValue) {
  const Vec3i n{37, 29, 41};
  for (TerrainStorage s : kStorages)
    for (bool positive_inside : {false, true}) {
      SCOPED_TRACE(std::string(terrain_storage_name(s)) + (positive_inside ? " +inside" : ""));
      TerrainOptions o = options_of(s, n);
      o.positive_inside = positive_inside;
      TerrainField t(o);
      const double clamp = t.max_distance_units();
      EXPECT_EQ(clamp, o.spacing_units * (s == TerrainStorage::kI8 ? 2 : 4));
      // Fresh: air at the clamp everywhere, one uniform chunk each.
      EXPECT_EQ(t.value({5, 6, 7}), (positive_inside ? -1 : 1) * quantised(s, clamp, clamp));
      EXPECT_EQ(t.memory().uniform_chunks, t.memory().chunks);
      const double sign = positive_inside ? -1 : 1;
      t.assign([&](const Vec3d& p) { return sign * ground(p); }, 3);
      std::vector<float> decoded(static_cast<std::size_t>(Box3i::from_size(n).volume()));
      t.decode(Box3i::from_size(n), decoded.data());
      std::size_t i = 0;
      for_each_sample(n, [&](Vec3i p) {
        const float want =
            static_cast<float>(sign) * quantised(s, clamp, ground(position(o, p.x, p.y, p.z)));
        ASSERT_EQ(t.value(p), want) << to_string(p);
        ASSERT_EQ(decoded[i++], want) << to_string(p);
        ASSERT_EQ(t.material(p), 3);
      });
      // Far from the ground every chunk is uniform (deep rock below, air above), and stored once.
      const TerrainField::Memory m = t.memory();
      EXPECT_GT(m.uniform_chunks, m.chunks / 3);
      EXPECT_LT(m.bytes, static_cast<std::uint64_t>(Box3i::from_size(n).volume()) *
                             (s == TerrainStorage::kI8    ? 1
                              : s == TerrainStorage::kI16 ? 2
                                                          : 4));
      // A region decoded on its own equals the same samples of the whole.
      const Box3i part{{3, 9, 11}, {30, 10, 33}};
      std::vector<float> piece(static_cast<std::size_t>(part.volume()));
      t.decode(part, piece.data());
      std::size_t j = 0;
      for (int z = part.begin.z; z < part.end.z; ++z)
        for (int y = part.begin.y; y < part.end.y; ++y)
          for (int x = part.begin.x; x < part.end.x; ++x) ASSERT_EQ(piece[j++], t.value({x, y, z}));
    }
}

// read_codes gives the stored codes, which decode (code * step, or the float) to what decode()
// gives in the negative-inside convention, and the materials material() gives — over a region
// that crosses uniform and dense chunks.
TEST(Terrain, RawCodesDecodeToTheSamples) {
  for (TerrainStorage s : kStorages)
    for (bool positive_inside : {false, true}) {
      SCOPED_TRACE(terrain_storage_name(s));
      TerrainOptions o = options_of(s, {29, 23, 21});
      o.positive_inside = positive_inside;
      TerrainField t(o);
      t.assign([&](const Vec3d& p) { return (positive_inside ? -1 : 1) * ground(p); }, 4);
      TerrainBrush b;
      b.centre_units = position(o, 14, 11, 14);
      b.radius_units = 2;
      b.material = 9;
      t.apply(b);
      const Box3i region{{3, 2, 1}, {27, 20, 19}};
      const int bytes = s == TerrainStorage::kI8 ? 1 : s == TerrainStorage::kI16 ? 2 : 4;
      std::vector<std::uint8_t> codes(static_cast<std::size_t>(region.volume() * bytes));
      std::vector<std::uint8_t> materials(static_cast<std::size_t>(region.volume()));
      t.read_codes(region, codes.data(), materials.data());
      std::size_t i = 0, wrong = 0;
      bool saw_nine = false;
      for (int z = region.begin.z; z < region.end.z; ++z)
        for (int y = region.begin.y; y < region.end.y; ++y)
          for (int x = region.begin.x; x < region.end.x; ++x, ++i) {
            float v;
            if (s == TerrainStorage::kI8) {
              v = static_cast<float>(static_cast<std::int8_t>(codes[i]) * t.step_units());
            } else if (s == TerrainStorage::kI16) {
              std::int16_t c;
              std::memcpy(&c, &codes[2 * i], 2);
              v = static_cast<float>(c * t.step_units());
            } else {
              std::memcpy(&v, &codes[4 * i], 4);
            }
            const float want = (positive_inside ? -1 : 1) * t.value({x, y, z});
            wrong += v != want || materials[i] != t.material({x, y, z});
            saw_nine |= materials[i] == 9;
          }
      EXPECT_EQ(wrong, 0u);
      EXPECT_TRUE(saw_nine);
      EXPECT_THROW(t.read_codes(Box3i{{0, 0, 0}, {30, 1, 1}}, codes.data()), InvalidArgument);
    }
}

TEST(Terrain, BrushesEqualTheirFormulaAppliedToEverySample) {
  const Vec3i n{34, 30, 27};
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (TerrainStorage s : kStorages) {
    SCOPED_TRACE(terrain_storage_name(s));
    const TerrainOptions o = options_of(s, n, 8);
    TerrainField t(o);
    t.assign(ground, 2);
    const double clamp = t.max_distance_units();
    int changed_any = 0;
    for (int round = 0; round < 24; ++round) {
      TerrainBrush b;
      b.shape = static_cast<TerrainBrush::Shape>(round % 3);
      b.mode = round % 2 ? TerrainBrush::Mode::kSubtract : TerrainBrush::Mode::kAdd;
      b.centre_units = position(o, static_cast<int>(u(rng) * n.x), static_cast<int>(u(rng) * n.y),
                                static_cast<int>(u(rng) * n.z / 2 + 4));
      b.centre_units.x += u(rng) * 0.3;
      b.end_units = b.centre_units + Vec3d{u(rng) * 4 - 2, u(rng) * 4 - 2, u(rng) * 2};
      b.radius_units = 0.4 + u(rng) * 3;
      b.half_extents_units = {0.3 + u(rng) * 3, 0.3 + u(rng) * 2, u(rng) * 2};
      b.smooth_units = round % 4 < 2 ? 0 : u(rng) * 2;
      b.material = static_cast<std::uint8_t>(10 + round);
      // The oracle: the formula on every sample of the field before the brush.
      std::vector<float> want_value;
      std::vector<std::uint8_t> want_material;
      Box3i want_box;
      for_each_sample(n, [&](Vec3i p) {
        const double d = t.value(p);
        const double bd = brush_sdf(b, position(o, p.x, p.y, p.z));
        const double next = b.mode == TerrainBrush::Mode::kAdd ? smin(d, bd, b.smooth_units)
                                                               : -smin(-d, bd, b.smooth_units);
        const float v = quantised(s, clamp, next);
        const std::uint8_t m =
            b.mode == TerrainBrush::Mode::kAdd && bd < d ? b.material : t.material(p);
        want_value.push_back(v);
        want_material.push_back(m);
        if (v != t.value(p) || m != t.material(p))
          want_box = want_box.unite({p, p + Vec3i{1, 1, 1}});
      });
      const Box3i got_box = t.apply(b);
      EXPECT_EQ(got_box, want_box) << "round " << round;
      changed_any += !got_box.empty();
      std::size_t i = 0;
      for_each_sample(n, [&](Vec3i p) {
        ASSERT_EQ(t.value(p), want_value[i]) << "round " << round << " at " << to_string(p);
        ASSERT_EQ(t.material(p), want_material[i]) << "round " << round << " at " << to_string(p);
        ++i;
      });
    }
    EXPECT_GT(changed_any, 16);
  }
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.positions, b.positions);
  ASSERT_EQ(a.normals, b.normals);
  ASSERT_EQ(a.colors, b.colors);
  ASSERT_EQ(a.indices, b.indices);
}

TEST(Terrain, MeshesEqualMeshesOfTheDecodedVolume) {
  const Vec3i n{40, 35, 30};
  for (TerrainStorage s : kStorages)
    for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring})
      for (int chunk_edge : {5, 16}) {
        SCOPED_TRACE(std::string(terrain_storage_name(s)) + " " + mesher_name(m) + " chunk " +
                     std::to_string(chunk_edge));
        const TerrainOptions o = options_of(s, n, 16);
        TerrainField t(o);
        t.assign(ground);
        TerrainBrush b;
        b.centre_units = position(o, 20, 17, 14);
        b.radius_units = 3;
        b.smooth_units = 1;
        t.apply(b);
        std::vector<float> decoded(static_cast<std::size_t>(Box3i::from_size(n).volume()));
        t.decode(Box3i::from_size(n), decoded.data());
        ScalarVolume v;
        v.size = n;
        v.values = decoded.data();
        v.origin_units = o.origin_units;
        v.spacing_units = {o.spacing_units, o.spacing_units, o.spacing_units};
        MeshOptions mo;
        mo.algorithm = m;
        mo.chunk_edge = chunk_edge;
        mo.iso = 0.75;  // ignored for a terrain: its surface is at 0
        const Mesh got = mesh_terrain(t, mo);
        mo.iso = 0;
        // The same chunked driver on the decoded volume, array for array; mesh_volume()'s
        // whole-volume passes (numbered by row, flying_edges.h) triangle for triangle.
        const Mesh want = MeshChunks(v, mo).merged();
        ASSERT_GT(want.triangle_count(), 1000u);
        expect_same_mesh(got, want);
        EXPECT_TRUE(test::corner_triangles(mesh_volume(v, mo)) == test::corner_triangles(want));
        // The thesis's positive-inside convention stores the same surface.
        TerrainOptions flipped = o;
        flipped.positive_inside = true;
        TerrainField f(flipped);
        f.assign([](const Vec3d& p) { return -ground(p); });
        f.apply(b);
        expect_same_mesh(mesh_terrain(f, mo), want);
      }
}

TEST(Terrain, VertexColoursComeFromTheInsideSamplesMaterial) {
  TerrainOptions o = options_of(TerrainStorage::kI16, {40, 40, 30}, 8);
  Palette palette{};
  palette[3] = {90, 70, 50, 255};
  palette[7] = {20, 200, 40, 255};
  o.palette = palette;
  TerrainField t(o);
  t.assign(ground, 3);
  TerrainBrush b;
  b.shape = TerrainBrush::Shape::kBox;
  b.centre_units = position(o, 20, 20, 18);
  b.half_extents_units = {3, 3, 3};
  b.material = 7;
  t.apply(b);
  for (Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring}) {
    MeshOptions mo;
    mo.algorithm = m;
    const Mesh mesh = mesh_terrain(t, mo);
    ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
    std::size_t box = 0, ground_vertices = 0;
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
      const Vec3d p{mesh.positions[i][0], mesh.positions[i][1], mesh.positions[i][2]};
      const double to_box = sdf::box(p - b.centre_units, b.half_extents_units);
      const std::array<std::uint8_t, 3> c = mesh.colors[i];
      if (to_box > 1.5 * o.spacing_units && std::abs(ground(p)) < 2) {
        EXPECT_EQ(c, (std::array<std::uint8_t, 3>{90, 70, 50})) << mesher_name(m);
        ++ground_vertices;
      } else if (std::abs(to_box) < 0.1 && ground(p) > 1.5) {  // the box's faces above the ground
        EXPECT_EQ(c, (std::array<std::uint8_t, 3>{20, 200, 40})) << mesher_name(m);
        ++box;
      }
    }
    EXPECT_GT(box, 50u);
    EXPECT_GT(ground_vertices, 500u);
  }
  o.palette.reset();
  TerrainField plain(o);
  plain.assign(ground, 3);
  EXPECT_TRUE(mesh_terrain(plain, {}).colors.empty());
}

TEST(Terrain, MeshChunksFollowBrushesExactly) {
  for (TerrainStorage s : {TerrainStorage::kI8, TerrainStorage::kF32}) {
    TerrainOptions o = options_of(s, {49, 41, 33}, 16);
    Palette palette{};
    for (int i = 0; i < 256; ++i)
      palette[static_cast<std::size_t>(i)] = {static_cast<std::uint8_t>(i), 7, 9, 255};
    o.palette = palette;
    for (Mesher m : {Mesher::kMarchingCubes, Mesher::kDualContouring}) {
      SCOPED_TRACE(std::string(terrain_storage_name(s)) + " " + mesher_name(m));
      TerrainField t(o);
      t.assign(ground, 1);
      MeshOptions mo;
      mo.algorithm = m;
      mo.chunk_edge = 8;
      MeshChunks chunks(t, mo);
      expect_same_mesh(chunks.merged(), mesh_terrain(t, mo));
      std::mt19937 rng(9);
      std::uniform_real_distribution<double> u(0, 1);
      const Vec3i count = chunks.chunk_count();
      for (int round = 0; round < 6; ++round) {
        TerrainBrush b;
        b.shape = static_cast<TerrainBrush::Shape>(round % 3);
        b.mode = round % 2 ? TerrainBrush::Mode::kSubtract : TerrainBrush::Mode::kAdd;
        b.centre_units =
            position(o, static_cast<int>(5 + u(rng) * 38), static_cast<int>(5 + u(rng) * 30), 0);
        b.centre_units.z = b.centre_units.z - ground(b.centre_units);  // on the ground
        b.end_units = b.centre_units + Vec3d{1.5, -1, 0.5};
        b.radius_units = 1 + u(rng) * 1.5;
        b.smooth_units = round % 3 == 0 ? 0.8 : 0;
        b.material = static_cast<std::uint8_t>(40 + round);
        const std::vector<Vec3i> redone = chunks.update(t, t.apply(b));
        EXPECT_GT(redone.size(), 0u);
        EXPECT_LT(static_cast<std::int64_t>(redone.size()),
                  static_cast<std::int64_t>(count.x) * count.y * count.z);
        expect_same_mesh(chunks.merged(), mesh_terrain(t, mo));
      }
      // A terrain of another frame is refused.
      TerrainOptions other = o;
      other.spacing_units = 0.25;
      EXPECT_THROW(chunks.update(TerrainField(other), Box3i{{0, 0, 0}, {1, 1, 1}}),
                   InvalidArgument);
      // So are a terrain without the palette and a volume: every chunk keeps colours or none.
      TerrainOptions plain = o;
      plain.palette.reset();
      EXPECT_THROW(chunks.update(TerrainField(plain), Box3i{{0, 0, 0}, {1, 1, 1}}),
                   InvalidArgument);
      std::vector<float> values(static_cast<std::size_t>(Box3i::from_size(o.samples).volume()));
      t.decode(Box3i::from_size(o.samples), values.data());
      ScalarVolume v;
      v.size = o.samples;
      v.values = values.data();
      v.origin_units = o.origin_units;
      v.spacing_units = {o.spacing_units, o.spacing_units, o.spacing_units};
      EXPECT_THROW(chunks.update(v, Box3i{{0, 0, 0}, {1, 1, 1}}), InvalidArgument);
      expect_same_mesh(chunks.merged(), mesh_terrain(t, mo));
    }
  }
}

// The quantisation's effect, measured: marching-cubes vertices of a sphere stored in each width,
// against the analytic surface. A vertex on an edge moves by the samples' rounding (half a step)
// divided by the edge's difference (about a spacing), so i16 stays with f32 and i8 within a few
// hundredths of a spacing of it.
TEST(Terrain, QuantisationMovesVerticesByAboutHalfAStep) {
  double worst[3] = {};
  const double radius = 9.3;
  for (int si = 0; si < 3; ++si) {
    TerrainOptions o = options_of(kStorages[si], {48, 48, 48}, 16);
    o.origin_units = {-12, -12, -12};
    TerrainField t(o);
    t.assign([&](const Vec3d& p) { return sdf::sphere(p, radius); });
    const Mesh mesh = mesh_terrain(t, {});
    ASSERT_GT(mesh.triangle_count(), 5000u);
    EXPECT_TRUE(mesh_stats(mesh).watertight());
    for (const auto& p : mesh.positions)
      worst[si] = std::max(worst[si], std::abs(sdf::sphere({p[0], p[1], p[2]}, radius)));
  }
  const double h = 0.5;  // the spacing
  // f32's error is the linear interpolation's alone (a sphere of radius 18.6 spacings).
  EXPECT_LT(worst[2], 0.01 * h);
  EXPECT_LT(worst[1], worst[2] + 0.001 * h);
  EXPECT_LT(worst[0], worst[2] + 0.05 * h);
  std::printf("max vertex distance to the sphere, in spacings: i8 %.5f, i16 %.5f, f32 %.5f\n",
              worst[0] / h, worst[1] / h, worst[2] / h);
}

TEST(Terrain, BadRequestsAreRefusedAndChangeNothing) {
  TerrainOptions o = options_of(TerrainStorage::kI16, {20, 20, 20});
  auto refused = [](TerrainOptions bad) { return error_of([&] { TerrainField t(bad); }); };
  TerrainOptions bad = o;
  bad.samples = {1, 20, 20};
  EXPECT_NE(refused(bad).find("2..65536"), std::string::npos);
  bad = o;
  bad.chunk_edge = 3;
  EXPECT_NE(refused(bad).find("chunk edge 3"), std::string::npos);
  bad = o;
  bad.spacing_units = 0;
  EXPECT_NE(refused(bad).find("spacing"), std::string::npos);
  bad = o;
  bad.max_distance_units = std::nan("");
  EXPECT_NE(refused(bad).find("clamp"), std::string::npos);
  bad = o;
  bad.max_distance_units = 1e-320;  // its step would underflow to zero
  EXPECT_NE(refused(bad).find("cannot be stored in i16"), std::string::npos);
  bad.storage = TerrainStorage::kF32;
  bad.max_distance_units = 1e300;  // no float holds it
  EXPECT_NE(refused(bad).find("cannot be stored in f32"), std::string::npos);
  bad = o;
  bad.origin_units[1] = INFINITY;
  EXPECT_NE(refused(bad).find("origin"), std::string::npos);
  EXPECT_THROW(parse_terrain_storage("i32"), InvalidArgument);

  TerrainField t(o);
  t.assign(ground, 4);
  const TerrainField before = t;
  const auto same = [&] {
    for (int z = 0; z < 20; ++z)
      for (int y = 0; y < 20; ++y)
        for (int x = 0; x < 20; ++x)
          if (t.value({x, y, z}) != before.value({x, y, z}) ||
              t.material({x, y, z}) != before.material({x, y, z}))
            return false;
    return true;
  };
  const std::string nan =
      error_of([&] { t.assign([](const Vec3d& p) { return p.x > 3 ? std::nan("") : 1.0; }); });
  EXPECT_NE(nan.find("NaN at sample"), std::string::npos) << nan;
  EXPECT_TRUE(same());
  TerrainBrush b;
  b.radius_units = 0;
  EXPECT_NE(error_of([&] { t.apply(b); }).find("radius"), std::string::npos);
  b.radius_units = 1;
  b.smooth_units = -1;
  EXPECT_NE(error_of([&] { t.apply(b); }).find("blend"), std::string::npos);
  b.smooth_units = 0;
  b.centre_units.y = std::nan("");
  EXPECT_NE(error_of([&] { t.apply(b); }).find("finite"), std::string::npos);
  b.centre_units.y = 0;
  b.shape = TerrainBrush::Shape::kBox;
  b.half_extents_units = {1, -1, 1};
  EXPECT_NE(error_of([&] { t.apply(b); }).find("half extents"), std::string::npos);
  EXPECT_TRUE(same());
  // Brushes entirely outside the lattice change nothing and say so.
  b.half_extents_units = {1, 1, 1};
  b.centre_units = {1000, 0, 0};
  EXPECT_TRUE(t.apply(b).empty());
  EXPECT_THROW(t.value({20, 0, 0}), InvalidArgument);
  EXPECT_THROW(t.material({0, -1, 0}), InvalidArgument);
  float out[8];
  EXPECT_THROW(t.decode(Box3i{{18, 18, 18}, {22, 19, 19}}, out), InvalidArgument);
  ScalarVolume wrong;
  wrong.size = {20, 20, 19};
  std::vector<float> values(20 * 20 * 19);
  wrong.values = values.data();
  EXPECT_THROW(t.assign(wrong), InvalidArgument);
  EXPECT_TRUE(same());
}

}  // namespace terrain_test
}  // namespace voxfield
