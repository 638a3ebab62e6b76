// Reading .vdb files (voxfield/vdb.h) against OpenVDB itself: grids of every type voxfield reads,
// written by OpenVDB with every compression it offers (none, zip, Blosc, with and without its
// active-mask compression), as files (with grid offsets) and as streams, in full and half
// precision, are read by voxfield's parser and by OpenVDB's, and compared voxel by voxel; then
// damaged files, which must each give an Error naming the file and never crash.
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetSphere.h>

#include <unistd.h>

#include <filesystem>
#include <random>
#include <sstream>

#include "error_text.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/vdb.h"
#include "voxfield/world_io.h"

namespace voxfield {
namespace vdb_read_test {

using test::error_of;

constexpr std::uint32_t kCompressions[] = {
    openvdb::io::COMPRESS_NONE,
    openvdb::io::COMPRESS_ZIP,
    openvdb::io::COMPRESS_ACTIVE_MASK,
    openvdb::io::COMPRESS_ZIP | openvdb::io::COMPRESS_ACTIVE_MASK,
    openvdb::io::COMPRESS_BLOSC,
    openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK,
};

std::vector<std::uint8_t> stream_bytes(const openvdb::GridPtrVec& grids, std::uint32_t c) {
  std::ostringstream out(std::ios_base::binary);
  openvdb::io::Stream s(out);
  s.setCompression(c);
  s.write(grids);
  const std::string text = out.str();
  return {text.begin(), text.end()};
}

// As io::File writes them: with grid offsets (so a reader can seek to one grid).
std::vector<std::uint8_t> file_bytes(const openvdb::GridPtrVec& grids, std::uint32_t c) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("voxfield-vdb-read-" + std::to_string(::getpid()) + ".vdb");
  {
    openvdb::io::File f(path.string());
    f.setCompression(c);
    f.write(grids);
    f.close();
  }
  std::vector<std::uint8_t> bytes = read_file(path);
  std::filesystem::remove(path);
  return bytes;
}

// OpenVDB's reading of the bytes, through io::File as a user's tool would read them.
openvdb::GridPtrVecPtr openvdb_read(const std::vector<std::uint8_t>& bytes) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("voxfield-vdb-oracle-" + std::to_string(::getpid()) + ".vdb");
  write_file_atomic(path, bytes);
  openvdb::io::File f(path.string());
  f.open(/*delayLoad=*/false);
  openvdb::GridPtrVecPtr grids = f.getGrids();
  f.close();
  std::filesystem::remove(path);
  return grids;
}

template <typename T>
std::array<double, 3> components(const T& v) {
  if constexpr (std::is_same_v<T, openvdb::Vec3f>)
    return {v[0], v[1], v[2]};
  else
    return {static_cast<double>(v), 0, 0};
}

// voxfield's reading of `got` against OpenVDB's of the same bytes: every value over the stored
// region and a margin, the active voxel count and bounds, the background and the transform.
template <typename GridT>
void expect_same(const openvdb::GridBase::Ptr& base, const VdbGrid& got, const std::string& what) {
  const auto ref = openvdb::gridPtrCast<GridT>(base);
  ASSERT_TRUE(ref) << what;
  EXPECT_EQ(got.name, ref->getName()) << what;
  EXPECT_EQ(got.grid_class, openvdb::GridBase::gridClassToString(ref->getGridClass())) << what;
  EXPECT_EQ(got.background, components(ref->background())) << what;
  for (const openvdb::Vec3d ijk : {openvdb::Vec3d(0, 0, 0), openvdb::Vec3d(3, -7, 11)}) {
    const openvdb::Vec3d w = ref->transform().indexToWorld(ijk);
    for (int a = 0; a < 3; ++a) {
      const double mine = got.index_to_world[4 * a] * ijk[0] +
                          got.index_to_world[4 * a + 1] * ijk[1] +
                          got.index_to_world[4 * a + 2] * ijk[2] + got.index_to_world[4 * a + 3];
      EXPECT_NEAR(mine, w[a], 1e-12) << what;
    }
  }
  std::int64_t active = 0;
  for (const VdbTile& t : got.tiles)
    if (t.active) active += std::int64_t{t.edge} * t.edge * t.edge;
  for (const VdbLeaf& l : got.leaves)
    for (int i = 0; i < got.leaf_edge * got.leaf_edge * got.leaf_edge; ++i)
      active += got.leaf_active(l, i);
  EXPECT_EQ(static_cast<openvdb::Index64>(active), ref->activeVoxelCount()) << what;
  const openvdb::CoordBBox bb = ref->evalActiveVoxelBoundingBox();
  const Box3i ab = got.active_bounds();
  EXPECT_EQ(ab.empty(), bb.empty()) << what;
  if (!bb.empty()) {
    EXPECT_EQ(ab.begin, (Vec3i{bb.min().x(), bb.min().y(), bb.min().z()})) << what;
    EXPECT_EQ(ab.end, (Vec3i{bb.max().x() + 1, bb.max().y() + 1, bb.max().z() + 1})) << what;
  }
  auto acc = ref->getConstAccessor();
  // Tiles larger than a leaf (a root tile spans 4096^3 voxels) are checked at their corners; the
  // leaves and leaf-sized tiles voxel by voxel, with a margin.
  Box3i box;
  for (const VdbTile& t : got.tiles) {
    if (t.edge <= 8) {
      box = box.unite(Box3i{t.origin, t.origin + Vec3i::splat(t.edge)});
      continue;
    }
    for (const Vec3i p : {t.origin, t.origin + Vec3i::splat(t.edge - 1)}) {
      EXPECT_EQ(t.value, components(acc.getValue(openvdb::Coord(p.x, p.y, p.z)))) << what;
      EXPECT_EQ(t.active, acc.isValueOn(openvdb::Coord(p.x, p.y, p.z))) << what;
    }
  }
  for (const VdbLeaf& l : got.leaves)
    box = box.unite(Box3i{l.origin, l.origin + Vec3i::splat(got.leaf_edge)});
  box = Box3i{box.begin - Vec3i::splat(2), box.end + Vec3i::splat(2)};
  ASSERT_LE(box.volume(), std::int64_t{1} << 23) << what;
  const std::vector<double> dense = got.dense(box);
  std::int64_t mismatches = 0;
  std::size_t i = 0;
  for (int z = box.begin.z; z < box.end.z; ++z)
    for (int y = box.begin.y; y < box.end.y; ++y)
      for (int x = box.begin.x; x < box.end.x; ++x, i += static_cast<std::size_t>(got.components)) {
        const auto want = components(acc.getValue(openvdb::Coord(x, y, z)));
        for (int c = 0; c < got.components; ++c)
          if (dense[i + static_cast<std::size_t>(c)] != want[static_cast<std::size_t>(c)]) {
            if (++mismatches <= 3)
              ADD_FAILURE() << what << ": (" << x << ", " << y << ", " << z << ") component " << c
                            << " reads " << dense[i + static_cast<std::size_t>(c)] << ", OpenVDB "
                            << want[static_cast<std::size_t>(c)];
          }
      }
  EXPECT_EQ(mismatches, 0) << what;
}

// Grids of every type voxfield reads, with leaves, tiles at two levels, inactive values other
// than the background, negative coordinates and a non-trivial transform.
openvdb::GridPtrVec sample_grids(bool half) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> at(-24, 24);
  std::uniform_real_distribution<float> value(-4, 4);
  openvdb::GridPtrVec grids;

  auto sphere = openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(
      /*radius=*/9.0f, openvdb::Vec3f(1.5f, -2.0f, 0.25f), /*voxelSize=*/0.25f);
  sphere->setName("sphere");
  sphere->setSaveFloatAsHalf(half);
  grids.push_back(sphere);

  auto ints = openvdb::Int32Grid::create(-3);
  ints->setName("ints");
  ints->fill(openvdb::CoordBBox({-4096, 0, 0}, {-1, 4095, 4095}), 42, /*active=*/true);
  ints->fill(openvdb::CoordBBox({128, 0, 0}, {255, 127, 127}), 9, /*active=*/false);
  ints->fill(openvdb::CoordBBox({64, 8, 8}, {71, 15, 15}), 6,
             /*active=*/true);  // a leaf-sized tile
  auto ia = ints->getAccessor();
  for (int n = 0; n < 3000; ++n) {
    const openvdb::Coord c(at(rng) + 80, at(rng), at(rng));
    if (n % 3 == 0)
      ia.setValueOff(c, n % 2 ? 5 : 3);  // a second and a third inactive value
    else
      ia.setValue(c, n);
  }
  ints->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
  ints->transform().postTranslate(openvdb::Vec3d(1, -2, 3));  // a uniform scale and translation
  ints->setSaveFloatAsHalf(half);  // marked half, though integers are stored whole
  ints->insertMeta("note", openvdb::StringMetadata("an int grid"));
  ints->insertMeta("corner", openvdb::Vec3IMetadata(openvdb::Vec3i(-1, 2, 3)));
  grids.push_back(ints);

  auto doubles = openvdb::DoubleGrid::create(0.5);
  doubles->setName("doubles");
  // Class unknown: OpenVDB drops zip compression from level sets and fog volumes, not from these.
  auto da = doubles->getAccessor();
  for (int n = 0; n < 2000; ++n) da.setValue(openvdb::Coord(at(rng), at(rng), at(rng)), value(rng));
  doubles->setSaveFloatAsHalf(half);
  openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
  m.preRotate(openvdb::math::Y_AXIS, 0.3);
  m.preScale(openvdb::Vec3d(0.5, 1, 2));
  m.postTranslate(openvdb::Vec3d(1, 2, 3));
  doubles->setTransform(openvdb::math::Transform::createLinearTransform(m));
  grids.push_back(doubles);

  auto bools = openvdb::BoolGrid::create(false);
  bools->setName("bools");
  auto ba = bools->getAccessor();
  for (int n = 0; n < 2000; ++n) ba.setValue(openvdb::Coord(at(rng), at(rng), at(rng)), n % 4 != 0);
  bools->fill(openvdb::CoordBBox({0, 0, 0}, {127, 127, 127}), true, true);
  bools->fill(openvdb::CoordBBox({-16, -16, -16}, {-9, -9, -9}), true, false);
  bools->setSaveFloatAsHalf(half);
  openvdb::math::Mat4d st = openvdb::math::Mat4d::identity();
  st.setToScale(openvdb::Vec3d(0.5, 2, 1));
  st.setTranslation(openvdb::Vec3d(-1, 0, 5));
  bools->setTransform(openvdb::math::Transform::createLinearTransform(st));  // scale, translate
  grids.push_back(bools);

  auto vectors = openvdb::Vec3SGrid::create(openvdb::Vec3f(0, 0, 1));
  vectors->setName("vectors");
  auto va = vectors->getAccessor();
  for (int n = 0; n < 2000; ++n)
    va.setValue(openvdb::Coord(at(rng), at(rng), at(rng)),
                openvdb::Vec3f(value(rng), value(rng), value(rng)));
  vectors->setSaveFloatAsHalf(half);
  openvdb::math::Mat4d t = openvdb::math::Mat4d::identity();
  t.setTranslation(openvdb::Vec3d(0.5, 0.25, -4));
  vectors->setTransform(openvdb::math::Transform::createLinearTransform(t));  // a translation
  grids.push_back(vectors);
  return grids;
}

TEST(VdbRead, EveryTypeAndCompressionReadsAsOpenVdbReadsIt) {
  openvdb::initialize();
  for (bool half : {false, true}) {
    const openvdb::GridPtrVec grids = sample_grids(half);
    for (std::uint32_t c : kCompressions)
      for (bool as_file : {false, true}) {
        const std::vector<std::uint8_t> bytes =
            as_file ? file_bytes(grids, c) : stream_bytes(grids, c);
        const std::string what = std::string(as_file ? "file" : "stream") + ", compression " +
                                 openvdb::io::compressionToString(c) + (half ? ", half" : "");
        const VdbFile got = decode_vdb(bytes, "sample.vdb");
        const openvdb::GridPtrVecPtr ref = openvdb_read(bytes);
        ASSERT_EQ(got.grids.size(), ref->size()) << what;
        EXPECT_EQ(got.format_version, openvdb::OPENVDB_FILE_VERSION) << what;
        // io::File lists grids by name; voxfield in the file's order, as they were written.
        auto named = [&](const char* name) {
          for (const auto& g : *ref)
            if (g->getName() == name) return g;
          return openvdb::GridBase::Ptr();
        };
        expect_same<openvdb::FloatGrid>(named("sphere"), got.grids[0], what + ", sphere");
        expect_same<openvdb::Int32Grid>(named("ints"), got.grids[1], what + ", ints");
        expect_same<openvdb::DoubleGrid>(named("doubles"), got.grids[2], what + ", doubles");
        expect_same<openvdb::BoolGrid>(named("bools"), got.grids[3], what + ", bools");
        expect_same<openvdb::Vec3SGrid>(named("vectors"), got.grids[4], what + ", vectors");
        EXPECT_EQ(got.grids[0].half_float, half) << what;
        EXPECT_EQ(got.grids[1].half_float, half) << what;  // an int grid marked half
        const VdbGrid& ints = got.grids[1];
        EXPECT_EQ(ints.metadata.at("note").text, "an int grid") << what;
        EXPECT_EQ(ints.metadata.at("corner").numbers, (std::vector<double>{-1, 2, 3})) << what;
        EXPECT_EQ(ints.voxel_size, (std::array<double, 3>{0.5, 0.5, 0.5})) << what;
      }
  }
}

// Grids sharing one tree are written once; the instance reads as a copy with its own transform.
// A grid of a type voxfield does not read is skipped in a file and refused in a stream (where
// nothing says where it ends).
TEST(VdbRead, InstancesShareTreesAndOtherTypesAreSkippedWhereTheFileAllows) {
  openvdb::initialize();
  auto a =
      openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(5.0f, openvdb::Vec3f(0.0f), 1.0f);
  a->setName("a");
  openvdb::GridBase::Ptr b = a->copyGrid();  // shares a's tree
  b->setTransform(openvdb::math::Transform::createLinearTransform(2.0));
  b->setName("b");
  auto other = openvdb::Vec3DGrid::create();
  other->setName("doubles3");
  other->tree().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3d(1, 2, 3));
  const openvdb::GridPtrVec grids{openvdb::GridBase::Ptr(a), openvdb::GridBase::Ptr(other),
                                  openvdb::GridBase::Ptr(b)};
  const std::vector<std::uint8_t> bytes = file_bytes(grids, openvdb::io::COMPRESS_BLOSC);
  const VdbFile got = decode_vdb(bytes, "instances.vdb");
  ASSERT_EQ(got.grids.size(), 2u);
  EXPECT_EQ(got.grids[1].name, "b");
  EXPECT_EQ(got.grids[1].instance_of, "a");
  EXPECT_EQ(got.grids[1].voxel_size, (std::array<double, 3>{2, 2, 2}));
  EXPECT_FALSE(got.grids[0].leaves.empty());
  const openvdb::GridPtrVecPtr ref = openvdb_read(bytes);
  for (const auto& g : *ref)
    if (g->getName() != "doubles3")
      expect_same<openvdb::FloatGrid>(g, got.grids[g->getName() == "a" ? 0 : 1],
                                      "instance " + g->getName());
  EXPECT_NE(error_of([&] {
              (void)decode_vdb(stream_bytes(grids, openvdb::io::COMPRESS_BLOSC), "s.vdb");
            }).find("s.vdb: at byte "),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              (void)decode_vdb(stream_bytes(grids, openvdb::io::COMPRESS_BLOSC), "s.vdb");
            }).find("Tree_vec3d_5_4_3"),
            std::string::npos);
}

World solid_world() {
  World w(16);
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> at(-30, 30), m(1, 255);
  for (int n = 0; n < 2000; ++n)
    w.voxels.set({at(rng), at(rng), at(rng)}, static_cast<std::uint8_t>(m(rng)));
  w.voxels.fill(Box3i{{-64, -32, 0}, {-32, 0, 32}}, 7);
  w.palette[9] = {1, 2, 3, 4};
  return w;
}

// --grid / LoadOptions::vdb_grid: the world comes from the grid of that name, read by its type's
// rule; OpenVDB's own iterators count what each rule should find. A missing name is refused with
// the file and the grids it has; a grid name for another format is refused too.
TEST(VdbRead, WorldsComeFromTheGridOfTheGivenName) {
  openvdb::initialize();
  const openvdb::GridPtrVec grids = sample_grids(false);
  const auto path = std::filesystem::temp_directory_path() /
                    ("voxfield-vdb-grid-" + std::to_string(::getpid()) + ".vdb");
  write_file_atomic(path, file_bytes(grids, openvdb::io::COMPRESS_BLOSC));
  const auto load = [&](const std::string& name) {
    LoadOptions o;
    o.vdb_grid = name;
    return load_world(path, o).world;
  };
  // Bools: active and true voxels, tiles included.
  std::int64_t active_true = 0;
  const auto bools = openvdb::gridConstPtrCast<openvdb::BoolGrid>(grids[3]);
  for (auto it = bools->cbeginValueOn(); it; ++it)
    if (*it) active_true += static_cast<std::int64_t>(it.getVoxelCount());
  EXPECT_EQ(load("bools").solid_count(), active_true);
  // The level set: the inside (value < 0), inactive interior tiles and leaf voxels alike.
  std::int64_t inside = 0;
  const auto sphere = openvdb::gridConstPtrCast<openvdb::FloatGrid>(grids[0]);
  for (auto it = sphere->cbeginValueAll(); it; ++it)
    if (*it < 0) inside += static_cast<std::int64_t>(it.getVoxelCount());
  EXPECT_GT(inside, 1000);
  EXPECT_EQ(load("sphere").solid_count(), inside);
  // Without a name the rule picks the Int32 grid "ints", whose values pass 255: refused by name.
  EXPECT_NE(error_of([&] { (void)load(""); }).find("grid \"ints\" has material"),
            std::string::npos);
  const std::string missing = error_of([&] { (void)load("density"); });
  EXPECT_NE(missing.find(path.string() + " has no grid named 'density'"), std::string::npos)
      << missing;
  EXPECT_NE(missing.find("'sphere' (float), 'ints' (int32), 'doubles' (double), 'bools' (bool), "
                         "'vectors' (vec3s)"),
            std::string::npos)
      << missing;
  std::filesystem::remove(path);
  const auto npy = std::filesystem::temp_directory_path() /
                   ("voxfield-vdb-grid-" + std::to_string(::getpid()) + ".npy");
  write_file_atomic(
      npy, encode_world(solid_world(), Box3i{{-64, -32, -32}, {32, 32, 32}}, WorldFormat::kNpy));
  LoadOptions o;
  o.vdb_grid = "bools";
  EXPECT_NE(error_of([&] { (void)load_world(npy, o); }).find("is for .vdb files"),
            std::string::npos);
  std::filesystem::remove(npy);
}

// voxfield's own .vdb files load back as the worlds they came from: materials, palette and
// extent from a world's file; the solid voxels from a signed field's level set.
TEST(VdbRead, VoxfieldsFilesLoadBackAsTheirWorlds) {
  World w = solid_world();
  w.frame.voxel_size_world = {0.5, 0.5, 2};
  const Box3i extent{{-70, -40, -35}, {40, 50, 41}};
  const auto path = std::filesystem::temp_directory_path() / "voxfield-vdb-read-world.vdb";
  write_file_atomic(path, encode_vdb_world(w, extent));
  const LoadedWorld back = load_world(path);
  std::filesystem::remove(path);
  EXPECT_EQ(back.format, WorldFormat::kVdb);
  EXPECT_EQ(back.extent, extent);
  EXPECT_EQ(back.world.palette, w.palette);
  EXPECT_NE(back.description.find("voxel size 0.5 x 0.5 x 2"), std::string::npos)
      << back.description;
  EXPECT_EQ(back.world.frame, w.frame);  // halves and quarters: exact in binary
  const Box3i c = w.voxels.content_bounds();
  ASSERT_EQ(back.world.voxels.content_bounds(), c);
  for (int z = c.begin.z; z < c.end.z; ++z)
    for (int y = c.begin.y; y < c.end.y; ++y)
      for (int x = c.begin.x; x < c.end.x; ++x)
        ASSERT_EQ(back.world.voxels.get({x, y, z}), w.voxels.get({x, y, z})) << x << " " << y;

  // The field measured in the frame's voxel size: a level set in the world's units.
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.spacing = {0.5, 0.5, 2};
  o.signed_distance = true;
  o.max_distance = 4;
  o.domain = Box3i{{-80, -50, -40}, {40, 40, 40}};
  const VdbFile field = decode_vdb(encode_vdb_field(compute_distance_field(w, o)), "f.vdb");
  const VdbWorld solid = world_from_vdb(field, "f.vdb", 32);
  EXPECT_EQ(solid.world.frame, w.frame);
  EXPECT_EQ(solid.world.solid_count(), w.solid_count());
  for (int z = c.begin.z; z < c.end.z; ++z)
    for (int y = c.begin.y; y < c.end.y; ++y)
      for (int x = c.begin.x; x < c.end.x; ++x)
        ASSERT_EQ(solid.world.voxels.get({x, y, z}) != 0, w.voxels.get({x, y, z}) != 0);
}

// A clipped read (an MPI rank's slab): the tiles and leaves that overlap the clip, exactly as a
// whole read has them, and nothing else held; the bounds still those of the whole tree; the world
// of a clipped read the whole world's voxels within the clip, for every grid type, compression
// and half floats. The dropped leaves' values are stepped over by their stored sizes: a wrong
// step would misread every leaf after them.
TEST(VdbRead, ClippedReadsKeepWhatOverlapsTheClipAndBoundTheRest) {
  openvdb::initialize();
  const Box3i clips[] = {Box3i{{-5, -7, -3}, {13, 6, 20}}, Box3i{},
                         Box3i{{-(1 << 20), -(1 << 20), 0}, {1 << 20, 1 << 20, 4}}};
  for (bool half : {false, true}) {
    const openvdb::GridPtrVec grids = sample_grids(half);
    for (std::uint32_t c : kCompressions) {
      const std::vector<std::uint8_t> bytes = file_bytes(grids, c);
      const VdbFile whole = decode_vdb(bytes, "sample.vdb");
      for (const Box3i& clip : clips) {
        const std::string what = "compression " + openvdb::io::compressionToString(c) +
                                 (half ? ", half" : "") + ", clip " + to_string(clip);
        VdbReadOptions o;
        o.clip = clip;
        const VdbFile part = decode_vdb(bytes, "sample.vdb", o);
        ASSERT_EQ(part.grids.size(), whole.grids.size()) << what;
        if (clip.empty()) {
          EXPECT_LT(part.memory_bytes(), whole.memory_bytes() / 4) << what;
        }
        for (std::size_t i = 0; i < whole.grids.size(); ++i) {
          const VdbGrid &w = whole.grids[i], &g = part.grids[i];
          const std::string grid = what + ", grid " + w.name;
          EXPECT_EQ(g.clip, clip) << grid;
          EXPECT_EQ(g.stored_bounds(), w.stored_bounds()) << grid;
          EXPECT_EQ(g.active_bounds(), w.active_bounds()) << grid;
          std::size_t t = 0;
          for (const VdbTile& tile : w.tiles) {
            const Box3i box{tile.origin, tile.origin + Vec3i::splat(tile.edge)};
            if (box.intersect(clip).empty()) continue;
            ASSERT_LT(t, g.tiles.size()) << grid;
            EXPECT_EQ(g.tiles[t].origin, tile.origin) << grid;
            EXPECT_EQ(g.tiles[t].value, tile.value) << grid;
            EXPECT_EQ(g.tiles[t++].active, tile.active) << grid;
          }
          EXPECT_EQ(t, g.tiles.size()) << grid;
          const std::size_t per_leaf =
              (std::size_t{1} << (3 * w.log2_dims.back())) * static_cast<std::size_t>(w.components);
          std::size_t l = 0;
          for (const VdbLeaf& leaf : w.leaves) {
            const Box3i box{leaf.origin, leaf.origin + Vec3i::splat(w.leaf_edge)};
            if (box.intersect(clip).empty()) continue;
            ASSERT_LT(l, g.leaves.size()) << grid;
            const VdbLeaf& kept = g.leaves[l++];
            ASSERT_EQ(kept.origin, leaf.origin) << grid;
            EXPECT_EQ(kept.active_bits, leaf.active_bits) << grid;
            for (std::size_t k = 0; k < per_leaf; ++k)
              ASSERT_EQ(g.leaf_value(kept.first_value + k), w.leaf_value(leaf.first_value + k))
                  << grid;
          }
          EXPECT_EQ(l, g.leaves.size()) << grid;
        }
        // The level set's inside, as a world: the whole one's voxels within the clip.
        const World in_whole = world_from_vdb(whole, "sample.vdb", 16, 0, "sphere").world;
        const VdbWorld in_part = world_from_vdb(part, "sample.vdb", 16, 0, "sphere");
        EXPECT_EQ(in_part.stored, whole.grids[0].stored_bounds()) << what;
        const Box3i content = in_whole.voxels.content_bounds();
        ASSERT_GT(content.volume(), 1000) << what;
        EXPECT_TRUE(clip.contains(in_part.world.voxels.content_bounds())) << what;
        for (int z = content.begin.z; z < content.end.z; ++z)
          for (int y = content.begin.y; y < content.end.y; ++y)
            for (int x = content.begin.x; x < content.end.x; ++x)
              ASSERT_EQ(in_part.world.voxels.get({x, y, z}),
                        clip.contains(Vec3i{x, y, z}) ? in_whole.voxels.get({x, y, z}) : 0)
                  << what << " at " << x << " " << y << " " << z;
      }
    }
  }
}

// Prefixes of files and hundreds of corrupted copies: an Error naming the file, or a
// successful read, never a crash (the ASan build runs this too).
TEST(VdbRead, DamagedFilesAreRefusedWithTheFileAndCause) {
  openvdb::initialize();
  auto g =
      openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(3.0f, openvdb::Vec3f(0.0f), 1.0f);
  auto ints = openvdb::Int32Grid::create(0);
  ints->tree().setValue(openvdb::Coord(-5, 6, 700), 3);
  for (std::uint32_t c : kCompressions) {
    const std::vector<std::uint8_t> bytes =
        file_bytes({openvdb::GridBase::Ptr(g), openvdb::GridBase::Ptr(ints)}, c);
    // Every one of the first 1000 bytes (the header, metadata, descriptors, transforms and masks)
    // of OpenVDB's default (Blosc, active mask), every 11th of the others, whose first kilobyte
    // differs only in the compression flags; then about 200 prefixes through the rest (an
    // uncompressed top node alone is 140 kB).
    const std::size_t near = c == kCompressions[5] ? 1 : 11;
    const std::size_t stride = std::max<std::size_t>(1, bytes.size() / 200);
    for (std::size_t n = 0; n < bytes.size(); n += n < 1000 ? near : stride) {
      const std::string e =
          error_of([&] { (void)decode_vdb(std::span(bytes.data(), n), "cut.vdb"); });
      ASSERT_EQ(e.rfind("cut.vdb: at byte ", 0), 0u) << n << ": " << e;
    }
    // Corrupted copies of the file and of the same grids as a stream; every other copy is hit in
    // its first 2000 bytes, where the structure is (leaf values make up most of the rest).
    const std::vector<std::uint8_t> stream =
        stream_bytes({openvdb::GridBase::Ptr(g), openvdb::GridBase::Ptr(ints)}, c);
    const std::size_t size = std::min(bytes.size(), stream.size());
    std::mt19937 rng(c);
    std::uniform_int_distribution<std::size_t> anywhere(0, size - 1);
    std::uniform_int_distribution<std::size_t> structure(0, std::min<std::size_t>(size, 2000) - 1);
    std::uniform_int_distribution<int> byte(0, 255);
    int refused = 0;
    for (int n = 0; n < 120; ++n) {
      std::vector<std::uint8_t> bad = n % 2 ? bytes : stream;
      for (int k = 0; k < 1 + n % 4; ++k)
        bad[(n / 2) % 2 ? structure(rng) : anywhere(rng)] = static_cast<std::uint8_t>(byte(rng));
      VdbReadOptions o;
      o.memory_limit_bytes = std::uint64_t{8} << 20;
      try {
        (void)world_from_vdb(decode_vdb(bad, "bad.vdb", o), "bad.vdb", 32, o.memory_limit_bytes);
      } catch (const Error& e) {
        ASSERT_NE(std::string(e.what()).find("bad.vdb"), std::string::npos) << e.what();
        ++refused;
      }
    }
    EXPECT_GT(refused, 6) << "the reader noticed almost none of the damage";
  }
  EXPECT_NE(error_of([] {
              (void)decode_vdb(std::vector<std::uint8_t>(64, 7), "x.vdb");
            }).find("x.vdb: at byte 0: not an OpenVDB file"),
            std::string::npos);
}

// A tree that would decode past the memory limit is refused before it is held.
TEST(VdbRead, TreesPastTheMemoryLimitAreRefused) {
  openvdb::initialize();
  auto g =
      openvdb::tools::createLevelSetSphere<openvdb::FloatGrid>(60.0f, openvdb::Vec3f(0.0f), 1.0f);
  const std::vector<std::uint8_t> bytes =
      file_bytes({openvdb::GridBase::Ptr(g)}, openvdb::io::COMPRESS_BLOSC);
  VdbReadOptions o;
  o.memory_limit_bytes = std::uint64_t{1} << 20;
  const std::string e = error_of([&] { (void)decode_vdb(bytes, "big.vdb", o); });
  EXPECT_NE(e.find("big.vdb"), std::string::npos) << e;
  EXPECT_NE(e.find("memory limit"), std::string::npos) << e;
}

}  // namespace vdb_read_test
}  // namespace voxfield
