// .vdb files (voxfield/vdb.h) against OpenVDB itself: what voxfield writes is read back here with
// OpenVDB's own stream reader and checked voxel by voxel against the world or field it came from,
// and a level set's volume is measured by OpenVDB's own tool.
#include <gtest/gtest.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetMeasure.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>

#include "error_text.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/vdb.h"
#include "voxfield/world_io.h"

namespace voxfield {
namespace vdb_test {

using test::error_of;

openvdb::GridPtrVecPtr grids_of(const std::vector<std::uint8_t>& bytes) {
  std::istringstream in(std::string(bytes.begin(), bytes.end()), std::ios_base::binary);
  return openvdb::io::Stream(in).getGrids();
}

// A world with materials 1..255 at negative and positive coordinates, uniform chunks and a palette
// of its own.
World sample_world() {
  World w(16);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> at(-40, 40), m(1, 255);
  for (int n = 0; n < 3000; ++n)
    w.voxels.set({at(rng), at(rng), at(rng)}, static_cast<std::uint8_t>(m(rng)));
  w.voxels.fill(Box3i{{-64, 0, 0}, {-32, 32, 16}}, 7);  // whole chunks: uniform
  for (int i = 0; i < 256; ++i)
    w.palette[static_cast<std::size_t>(i)] = {static_cast<std::uint8_t>(i), 3, 200,
                                              static_cast<std::uint8_t>(255 - i)};
  return w;
}

TEST(Vdb, WorldsAreInt32MaterialGridsWithTheirPaletteAndExtent) {
  World w = sample_world();
  w.frame.voxel_size_world = {0.5, 0.5, 2};
  const Box3i extent{{-70, -50, -45}, {50, 60, 41}};
  const std::vector<std::uint8_t> bytes = encode_vdb_world(w, extent);
  // OpenVDB's view: one Int32 grid whose active voxels are the solid voxels with their material.
  const openvdb::GridPtrVecPtr grids = grids_of(bytes);
  ASSERT_EQ(grids->size(), 1u);
  const auto grid = openvdb::gridPtrCast<openvdb::Int32Grid>((*grids)[0]);
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->getName(), "materials");
  EXPECT_EQ(static_cast<std::int64_t>(grid->activeVoxelCount()), w.solid_count());
  EXPECT_EQ(grid->transform().voxelSize(), openvdb::Vec3d(0.5, 0.5, 2));
  // Index (i, j, k) maps to the voxel's centre in the frame, ((i, j, k) + 1/2) * size.
  EXPECT_EQ(grid->transform().indexToWorld(openvdb::Coord(-3, 4, 5)),
            openvdb::Vec3d(-1.25, 2.25, 11));
  const Box3i content = w.voxels.content_bounds();
  auto access = grid->getConstAccessor();
  std::int64_t checked = 0;
  for (int z = content.begin.z; z < content.end.z; ++z)
    for (int y = content.begin.y; y < content.end.y; ++y)
      for (int x = content.begin.x; x < content.end.x; ++x) {
        const std::uint8_t m = w.voxels.get({x, y, z});
        const openvdb::Coord c(x, y, z);
        ASSERT_EQ(access.getValue(c), m) << x << " " << y << " " << z;
        ASSERT_EQ(access.isValueOn(c), m != 0);
        ++checked;
      }
  EXPECT_GT(checked, 100000);
  // The palette and extent in the metadata.
  std::string palette;
  for (const Rgba& c : w.palette) {
    char hex[9];
    std::snprintf(hex, sizeof hex, "%02x%02x%02x%02x", c.r, c.g, c.b, c.a);
    palette += hex;
  }
  EXPECT_EQ(grid->metaValue<std::string>("voxfield_palette"), palette);
  EXPECT_EQ(grid->metaValue<std::string>("voxfield_kind"), "world");
  EXPECT_EQ(grid->metaValue<openvdb::Vec3i>("voxfield_extent_min"), openvdb::Vec3i(-70, -50, -45));
  EXPECT_EQ(grid->metaValue<openvdb::Vec3i>("voxfield_extent_max"), openvdb::Vec3i(49, 59, 40));
  // Uniform chunks were written as tiles, not as voxels.
  EXPECT_GT(grid->tree().activeTileCount(), 0u);
  World flat = w;
  flat.frame.voxel_size_world = {1, 0, 1};
  EXPECT_THROW((void)encode_vdb_world(flat, extent), InvalidArgument);
}

// A world in a rotated, anisotropic, displaced frame: OpenVDB's own transform puts every voxel
// centre where the frame does, and the file reads back in the same frame.
TEST(Vdb, AWorldsFrameIsItsGridsTransform) {
  World w = sample_world();
  w.frame.origin_world = {100.25, -7, 3.5};
  w.frame.voxel_size_world = {0.1, 0.2, 0.3};
  w.frame.rotation = VectorVolume::rotation_about(40, {1, -1, 2});
  const Box3i extent = w.voxels.content_bounds();
  const std::vector<std::uint8_t> bytes = encode_vdb_world(w, extent);
  const auto grid = openvdb::gridPtrCast<openvdb::Int32Grid>((*grids_of(bytes))[0]);
  ASSERT_TRUE(grid);
  double worst = 0;
  for (const Vec3i v : {Vec3i{0, 0, 0}, Vec3i{-5, 17, 3}, extent.begin, extent.end}) {
    const openvdb::Vec3d got = grid->transform().indexToWorld(openvdb::Coord(v.x, v.y, v.z));
    const Vec3d want = w.frame.voxel_centre_world(v);
    for (int a = 0; a < 3; ++a) worst = std::max(worst, std::abs(got[a] - want[a]));
  }
  EXPECT_LT(worst, 1e-12);
  const VdbWorld back = world_from_vdb(decode_vdb(bytes, "framed.vdb"), "framed.vdb", 16);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(back.world.frame.origin_world[a], w.frame.origin_world[a], 1e-12);
    EXPECT_NEAR(back.world.frame.voxel_size_world[a], w.frame.voxel_size_world[a], 1e-15);
    for (int b = 0; b < 3; ++b)
      EXPECT_NEAR(back.world.frame.rotation[a][b], w.frame.rotation[a][b], 1e-14);
  }
  // A field of the framed world, measured in its voxel size, is written in world units; measured
  // in voxels (an isotropic frame), its values are scaled; out of proportion, refused.
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.max_distance = 4;
  o.spacing = {0.1, 0.2, 0.3};
  DistanceField f = compute_distance_field(w, o);
  const auto lf = openvdb::gridPtrCast<openvdb::FloatGrid>((*grids_of(encode_vdb_field(f)))[0]);
  ASSERT_TRUE(lf);
  EXPECT_NEAR(lf->transform().indexToWorld(openvdb::Coord(2, 3, 4))[0],
              w.frame.voxel_centre_world({2, 3, 4}).x, 1e-12);
  EXPECT_NEAR(lf->background(), 4 - 0.05, 1e-6);  // the clamp less half the smallest edge
  EXPECT_EQ(lf->metaValue<double>("voxfield_max_distance"), 4);
  World iso = w;
  iso.frame.voxel_size_world = {0.25, 0.25, 0.25};
  DistanceOptions unit = o;
  unit.spacing = {1, 1, 1};
  const DistanceField fi = compute_distance_field(iso, unit);
  const auto li = openvdb::gridPtrCast<openvdb::FloatGrid>((*grids_of(encode_vdb_field(fi)))[0]);
  EXPECT_NEAR(li->background(), (4 - 0.5) * 0.25, 1e-6);         // voxels times the edge
  EXPECT_EQ(li->metaValue<double>("voxfield_max_distance"), 1);  // in world units too
  const Vec3i p = w.voxels.content_bounds().begin;
  EXPECT_NEAR(li->tree().getValue(openvdb::Coord(p.x, p.y, p.z)),
              0.25 * (fi.distance(p) + (fi.distance(p) < 0 ? 0.5 : -0.5)), 1e-6);
  const DistanceField skewed = compute_distance_field(w, unit);
  EXPECT_THROW((void)encode_vdb_field(skewed), InvalidArgument);
}

World blob_world() {
  World w(16);
  for (int z = 0; z < 24; ++z)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 28; ++x) {
        const double dx = x - 12.3, dy = y - 9.1, dz = z - 11.7;
        if (dx * dx + dy * dy * 1.4 + dz * dz < 64 || (x > 20 && y < 6 && z < 9))
          w.voxels.set({x, y, z}, 3);
      }
  return w;
}

// Every metric, sign, clamp and storage: the grid's class, background and voxel size, and at every
// voxel of the domain OpenVDB reads the field's distance (clamped to the background), active where
// it lies below the background.
// A world's flow in a rotated, anisotropic frame: on the world's lattice (OpenVDB's transform puts
// texel (i, j, k) of the box at the frame's centre of voxel box.begin + (i, j, k)), each direction
// carried into the world — R * (size ⊙ d), normalised — times its strength.
TEST(Vdb, AWorldsFlowIsWrittenInItsFrame) {
  VoxelFrame frame;
  frame.origin_world = {3, -1, 7};
  frame.voxel_size_world = {0.5, 1, 2};
  frame.rotation = VectorVolume::rotation_about(60, {0, 0, 1});
  const Box3i box{{-2, 3, 1}, {2, 6, 3}};
  VectorTexture t(box.size(), VectorStorage::kRgba32f);
  const VectorTexel texels[] = {{1, 0, 0, 0.5f}, {0, 0.6f, 0.8f, 1}, {0, 0, -1, 0.25f}};
  for (std::int64_t i = 0; i < 3; ++i) t.set(i * 7, texels[i]);
  const auto grids = grids_of(encode_vdb_world_vectors(box, t, frame));
  openvdb::Vec3SGrid::Ptr vectors;
  for (const auto& g : *grids)
    if (g->getName() == "vectors") vectors = openvdb::gridPtrCast<openvdb::Vec3SGrid>(g);
  ASSERT_TRUE(vectors);
  EXPECT_EQ(static_cast<int>(vectors->activeVoxelCount()), 3);
  const Vec3i n = box.size();
  for (std::int64_t i = 0; i < 3; ++i) {
    const std::int64_t at = i * 7;
    const Vec3i v = box.begin + Vec3i{static_cast<int>(at % n.x), static_cast<int>(at / n.x % n.y),
                                      static_cast<int>(at / (n.x * n.y))};
    const openvdb::Coord c(v.x, v.y, v.z);
    const openvdb::Vec3d centre = vectors->transform().indexToWorld(c);
    const Vec3d want_centre = frame.voxel_centre_world(v);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(centre[a], want_centre[a], 1e-12);
    const VectorTexel& d = texels[i];
    const Vec3d world = frame.world_direction({d.x, d.y, d.z}).normalized() * d.strength;
    const openvdb::Vec3f got = vectors->tree().getValue(c);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(got[a], world[a], 1e-6) << i << " axis " << a;
  }
}

TEST(Vdb, FieldsAreLevelSetsOrScalarGridsHoldingTheirDistances) {
  const World w = blob_world();
  int cases = 0;
  for (Metric metric : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool is_signed : {false, true})
      for (double clamp : {0.0, 3.0, 3.1, 3.3, 40.0})  // 3.1, 3.3: not stored exactly; 40: past u8
        for (Storage storage : {Storage::kU8, Storage::kF32}) {
          DistanceOptions o;
          o.metric = metric;
          o.signed_distance = is_signed;
          o.max_distance = clamp;
          o.storage = storage;
          if (metric == Metric::kEuclidean) o.spacing = {1, 2, 0.5};
          o.domain = Box3i{{-3, -2, -4}, {31, 23, 27}};
          const DistanceField f = compute_distance_field(w, o);
          const auto grid =
              openvdb::gridPtrCast<openvdb::FloatGrid>((*grids_of(encode_vdb_field(f)))[0]);
          ASSERT_TRUE(grid);
          const std::string what = std::string(metric_name(metric)) + (is_signed ? " signed" : "") +
                                   " clamp " + std::to_string(clamp) + " " + storage_name(storage);
          EXPECT_EQ(grid->getGridClass(),
                    is_signed ? openvdb::GRID_LEVEL_SET : openvdb::GRID_UNKNOWN)
              << what;
          EXPECT_EQ(grid->transform().voxelSize(),
                    openvdb::Vec3d(o.spacing[0], o.spacing[1], o.spacing[2]))
              << what;
          // A level set is the distance to the surface, half a voxel (of the smallest edge) in.
          const double half =
              is_signed ? 0.5 * std::min({o.spacing[0], o.spacing[1], o.spacing[2]}) : 0;
          const auto level = [&](double d) { return d > 0 ? d - half : d < 0 ? d + half : d; };
          double largest = 0;
          for (const Vec3i p : {Vec3i{-3, -2, -4}, Vec3i{30, 22, 26}, Vec3i{12, 9, 11}})
            largest = std::max(largest, std::abs(level(f.distance(p))));
          const float bg = grid->background();
          // Clamped: the clamp as stored (what every voxel beyond it and outside the domain reads).
          const double stored = level(f.distance({1000, 1000, 1000}));
          if (clamp > 0)
            EXPECT_EQ(bg, static_cast<float>(stored)) << what;
          else
            EXPECT_GE(bg, static_cast<float>(largest)) << what;
          if (clamp == 3) {
            EXPECT_EQ(bg, static_cast<float>(clamp - half)) << what;
          }
          EXPECT_EQ(grid->metaValue<double>("voxfield_surface_offset"), half) << what;
          auto access = grid->getConstAccessor();
          for (int z = o.domain->begin.z; z < o.domain->end.z; ++z)
            for (int y = o.domain->begin.y; y < o.domain->end.y; ++y)
              for (int x = o.domain->begin.x; x < o.domain->end.x; ++x) {
                const double d = level(f.distance({x, y, z}));
                const float want = static_cast<float>(
                    std::clamp(d, -static_cast<double>(bg), static_cast<double>(bg)));
                const openvdb::Coord c(x, y, z);
                ASSERT_EQ(access.getValue(c), want) << what << " at " << x << " " << y << " " << z;
                ASSERT_EQ(access.isValueOn(c), std::abs(d) < bg) << what << " at " << x << " " << y;
              }
          ++cases;
        }
  EXPECT_EQ(cases, 60);
}

// A clamped level set keeps only a band active: its inside far from the surface lives in inactive
// tiles at -background. Every solid voxel reads negative and every air voxel positive, tiles and
// background included, and OpenVDB's own measure of the level set's volume is the solid volume.
TEST(Vdb, LevelSetsAreClosedAndEncloseTheSolidVolume) {
  World w(16);
  w.voxels.fill(Box3i{{-40, -40, -40}, {40, 40, 40}}, 9);  // uniform inside chunks -> tiles
  w.voxels.set({50, 0, 0}, 9);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.max_distance = 1;  // 2 voxels
  o.spacing = {0.5, 0.5, 0.5};
  o.domain = Box3i{{-48, -48, -48}, {56, 48, 48}};
  const std::vector<std::uint8_t> bytes = encode_vdb_field(compute_distance_field(w, o), "sdf");
  const auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>((*grids_of(bytes))[0]);
  ASSERT_TRUE(grid);
  EXPECT_EQ(grid->getName(), "sdf");
  EXPECT_LT(grid->activeVoxelCount(), 84u * 84 * 6 * 4);  // a band, not the 80^3 block
  std::int64_t inside_tiles = 0;  // the inside, as inactive tiles at -background
  for (auto it = grid->tree().cbeginValueOff(); it; ++it)
    inside_tiles += it.isTileValue() && *it == -grid->background();
  EXPECT_GT(inside_tiles, 0);
  auto access = grid->getConstAccessor();
  for (int z = -60; z < 60; z += 3)
    for (int y = -60; y < 60; y += 3)
      for (int x = -60; x < 70; ++x) {
        const float v = access.getValue(openvdb::Coord(x, y, z));
        ASSERT_EQ(v < 0, w.voxels.get({x, y, z}) != 0) << x << " " << y << " " << z << ": " << v;
      }
  // The block is 80^3 voxels of 0.5^3 units, plus one voxel.
  const double want = (80.0 * 80 * 80 + 1) * 0.125;
  EXPECT_NEAR(openvdb::tools::levelSetVolume(*grid), want, 0.01 * want);
}

// A field's .vdb joined from two parts (voxfield-mpi's slabs) is the whole field's file but for the
// stream's UUID (bytes 21-57, random in every file OpenVDB writes); the joined grid is charged to
// the memory limit as each part comes in, and a part past it is refused by name.
TEST(Vdb, FieldsJoinedFromPartsAreTheWholeFieldsFileWithinTheMemoryLimit) {
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.max_distance = 3;
  o.domain = Box3i{{-4, -4, -4}, {32, 24, 28}};
  const DistanceField whole = compute_distance_field(blob_world(), o);
  DistanceField lower = whole, upper = whole;
  lower.domain.end.z = 13;  // not a multiple of 8: the leaves at z 8..15 are split between them
  upper.domain.begin.z = 13;
  const double background = vdb_field_background(whole);
  ASSERT_EQ(background, std::max(vdb_field_background(lower), vdb_field_background(upper)));
  const std::vector<std::uint8_t> part = encode_vdb_field_part(upper, background, whole.domain);
  VdbFieldParts joined(lower, background, whole.domain);
  joined.add(part, "the upper part");
  const std::vector<std::uint8_t> want = encode_vdb_field(whole), got = joined.finish();
  ASSERT_EQ(got.size(), want.size());
  EXPECT_TRUE(std::equal(got.begin(), got.begin() + 21, want.begin()));
  EXPECT_TRUE(std::equal(got.begin() + 57, got.end(), want.begin() + 57));

  // Each part's tree as OpenVDB holds it (read whole, not delay-loaded), and a limit above
  // either alone but below both: the joined tree and the incoming part's are charged together.
  const auto usage = [](const std::vector<std::uint8_t>& bytes) {
    std::istringstream in(std::string(bytes.begin(), bytes.end()), std::ios_base::binary);
    const openvdb::GridPtrVecPtr grids = openvdb::io::Stream(in, false).getGrids();
    return static_cast<std::uint64_t>(
        openvdb::gridPtrCast<openvdb::FloatGrid>(grids->front())->tree().memUsage());
  };
  const std::uint64_t a = usage(encode_vdb_field_part(lower, background, whole.domain)),
                      b = usage(part);
  struct LimitGuard {
    ~LimitGuard() { set_default_memory_limit(0); }
  } guard;
  VdbFieldParts tight(lower, background, whole.domain);
  set_default_memory_limit(std::max(a, b) + std::min(a, b) / 2);
  const std::string refusal = error_of([&] { tight.add(part, "the upper part"); });
  EXPECT_NE(refusal.find("the upper part"), std::string::npos) << refusal;
  EXPECT_NE(refusal.find("memory limit"), std::string::npos) << refusal;
}

// Unclamped fields of empty worlds have nothing to bound their background; bad names of outputs
// and a missing .vdb file are refused with the reason.
TEST(Vdb, RefusalsSayWhy) {
  DistanceOptions o;
  o.domain = Box3i{{0, 0, 0}, {4, 4, 4}};
  const DistanceField empty = compute_distance_field(World{}, o);
  EXPECT_NE(error_of([&] { (void)encode_vdb_field(empty); }).find("nothing bounds"),
            std::string::npos);
  const std::string missing = error_of([] { (void)load_world("x.vdb"); });
  EXPECT_EQ(missing.rfind("x.vdb", 0), 0u) << missing;
}

}  // namespace vdb_test
}  // namespace voxfield
