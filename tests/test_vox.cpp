// MagicaVoxel import/export against the shared corpus (../shared/data/vox, whose README records
// model counts, voxel counts and world extents measured by an independent chunk walker) and
// against hand-made files.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <optional>
#include <utility>

#include "vox_builder.h"
#include "voxfield/file.h"
#include "voxfield/vox.h"
#include "world_voxels.h"

using namespace voxfield;
using namespace voxfield::test;

namespace {

const std::filesystem::path kCorpus = VOXFIELD_VOX_CORPUS;

struct CorpusFile {
  const char* name;
  int models;
  std::int64_t voxels;          // sum of the models' stored voxel counts
  std::optional<Vec3i> extent;  // scene-graph world extent, when the README gives one
};

// From ../shared/data/vox/README.md.
const CorpusFile kFiles[] = {
    {"ephtracy_chr_knight.vox", 1, 398, {}},
    {"ephtracy_chr_cat.vox", 1, 563, {}},
    {"ephtracy_dragon.vox", 1, 40265, {}},
    {"ephtracy_teapot.vox", 1, 28411, {}},
    {"ephtracy_menger.vox", 1, 160000, {}},
    {"ephtracy_snow.vox", 1, 1296, {}},
    {"ephtracy_maze2D.vox", 1, 7938, {}},
    {"ephtracy_monu3.vox", 1, 848469, {}},
    {"ephtracy_monu10.vox", 1, 150764, {}},
    {"ephtracy_T-Rex.vox", 8, 10219, {}},
    {"ogt_test_multiple_model_scene.vox", 41, 6053, Vec3i{106, 106, 16}},
    {"ogt_test_groups.vox", 15, 1682, Vec3i{92, 21, 48}},
    {"ogt_test_meta_chunk.vox", 1, 64000, Vec3i{40, 40, 40}},
    {"ogt_doom.vox", 1, 3894, Vec3i{126, 126, 126}},
    {"jgraef_test_no_models.vox", 0, 0, {}},
    {"jgraef_test_materials.vox", 1, 5, Vec3i{3, 1, 3}},
    {"dotvox_axes.vox", 4, 4372, Vec3i{260, 287, 199}},
    {"dotvox_metal-material.vox", 1, 20, Vec3i{3, 3, 3}},
    {"vengi_test-transform.vox", 3, 126806, Vec3i{256, 256, 129}},
    {"vengi_8ontop.vox", 8, 1344, Vec3i{452, 491, 80}},
    {"vengi_test_material.vox", 12, 768000, Vec3i{342, 40, 202}},
    {"vengi_robo.vox", 3, 1291, Vec3i{22, 21, 30}},
    {"qinzhuo_teapot1.vox", 1, 394251, Vec3i{256, 256, 256}},
    {"qinzhuo_cars.vox", 5, 16298, Vec3i{101, 68, 65}},
    {"kluchek_phantom_mansion.vox", 17, 633134, Vec3i{359, 360, 367}},
    {"kluchek_skyscraper_03_000.vox", 3, 161089, Vec3i{65, 65, 201}},
    {"mmmm_scene_store8.vox", 1, 441118, {}},
    {"mmmm_chr_mayor.vox", 1, 340, {}},
};

class Corpus : public ::testing::TestWithParam<CorpusFile> {};

// Readable test parameter names in failure messages.
[[maybe_unused]] void PrintTo(const CorpusFile& f, std::ostream* os) {
  *os << f.name;
}

}  // namespace

TEST_P(Corpus, MatchesTheCorpusReadme) {
  const CorpusFile& f = GetParam();
  const VoxImport in = read_vox(kCorpus / f.name);
  ASSERT_EQ(static_cast<int>(in.info.models.size()), f.models);
  std::int64_t stored = 0;
  for (const auto& m : in.info.models) stored += m.voxel_count;
  EXPECT_EQ(stored, f.voxels);
  if (f.extent) {
    Box3i box{{0, 0, 0}, {0, 0, 0}};
    for (const auto& inst : in.info.instances)
      if (!inst.hidden) box = box.unite(inst.world_box);
    EXPECT_EQ(box.size(), *f.extent);
  }
  // Single models placed once: every stored voxel lands in the world.
  const bool single_instance = in.info.models.size() == 1 && in.info.instances.size() <= 1;
  if (single_instance) {
    EXPECT_EQ(in.world.solid_count(), f.voxels);
  }
  // Export, import again: the same world, voxel for voxel, and the same palette.
  const VoxImport back = parse_vox(encode_vox(in.world), "re-encoded");
  const Box3i content = in.world.voxels.content_bounds();
  EXPECT_EQ(back.world.voxels.content_bounds(), content);
  EXPECT_EQ(back.world.solid_count(), in.world.solid_count());
  if (!content.empty()) {
    EXPECT_TRUE(test::dense_voxels(back.world, content) == test::dense_voxels(in.world, content));
  }
  for (int m = 1; m < 256; ++m) EXPECT_EQ(back.world.palette[m], in.world.palette[m]) << m;
}

// A slab (VoxImportOptions::keep_z) places exactly the whole world's voxels within it and no
// other, and the scene's description (the extent the slabs are cut from) is the whole file's.
TEST_P(Corpus, SlabsPlaceExactlyTheirVoxels) {
  const CorpusFile& f = GetParam();
  const std::vector<std::uint8_t> bytes = read_file(kCorpus / f.name);
  const VoxImport whole = parse_vox(bytes, f.name);
  const Box3i extent = vox_extent(whole.info);
  if (extent.empty()) {  // a file without models: no slab places anything
    VoxImportOptions o;
    o.keep_z = std::pair<std::int32_t, std::int32_t>{-10, 10};
    EXPECT_EQ(parse_vox(bytes, f.name, o).world.solid_count(), 0);
    return;
  }
  const int z0 = extent.begin.z, z1 = extent.end.z, mid = (z0 + z1) / 2;
  // Below the extent into its middle, the rest and past it, one slice, and none.
  for (const auto& [a, b] : {std::pair{z0 - 5, mid}, std::pair{mid, z1 + 7},
                             std::pair{mid, mid + 1}, std::pair{mid, mid}}) {
    SCOPED_TRACE("z in [" + std::to_string(a) + ", " + std::to_string(b) + ")");
    VoxImportOptions o;
    o.keep_z = std::pair<std::int32_t, std::int32_t>{a, b};
    const VoxImport slab = parse_vox(bytes, f.name, o);
    EXPECT_EQ(vox_extent(slab.info), extent);
    EXPECT_EQ(slab.info.instances.size(), whole.info.instances.size());
    Box3i box = extent;
    box.begin.z = std::max(a, z0);
    box.end.z = std::min(b, z1);
    const Box3i content = slab.world.voxels.content_bounds();
    if (box.empty()) {
      EXPECT_TRUE(content.empty());
      continue;
    }
    EXPECT_TRUE(content.empty() || box.unite(content) == box) << "voxels outside the slab";
    EXPECT_TRUE(test::dense_voxels(slab.world, box) == test::dense_voxels(whole.world, box));
  }
}

INSTANTIATE_TEST_SUITE_P(SharedCorpus, Corpus, ::testing::ValuesIn(kFiles), [](const auto& info) {
  std::string n = info.param.name;
  for (char& c : n)
    if (!isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
});

TEST(Vox, MengerSpongeHasExactly160000Voxels) {
  const VoxImport in = read_vox(kCorpus / "ephtracy_menger.vox");
  EXPECT_EQ(in.world.solid_count(), 160000);  // 20^4: level-4 Menger sponge
  EXPECT_EQ(in.world.voxels.content_bounds(), Box3i::from_size({81, 81, 81}));
  // The sponge's central tunnel is open all the way through.
  for (int z = 0; z < 81; ++z) EXPECT_EQ(in.world.voxels.get({40, 40, z}), 0);
}

TEST(Vox, MetaChunkFileIsASolid40Cube) {
  const VoxImport in = read_vox(kCorpus / "ogt_test_meta_chunk.vox");
  EXPECT_EQ(in.info.version, 200);
  const Box3i b = in.world.voxels.content_bounds();
  EXPECT_EQ(b.size(), (Vec3i{40, 40, 40}));
  EXPECT_EQ(in.world.solid_count(), 40 * 40 * 40);
  EXPECT_EQ(in.world.solid_count(), b.volume());  // solid: no holes in its box
}

TEST(Vox, MissingRgbaMeansTheDefaultPalette) {
  const VoxImport cat = read_vox(kCorpus / "ephtracy_chr_cat.vox");
  EXPECT_FALSE(cat.info.has_palette);
  EXPECT_EQ(cat.world.palette, default_palette());
  const Palette p = default_palette();
  EXPECT_EQ(p[1], (Rgba{255, 255, 255, 255}));  // first cube entry: white
  EXPECT_EQ(p[2], (Rgba{255, 255, 0xCC, 255}));
  EXPECT_EQ(p[215], (Rgba{0, 0, 0x33, 255}));  // last cube entry before black
  EXPECT_EQ(p[216], (Rgba{0xEE, 0, 0, 255}));  // red ramp
  EXPECT_EQ(p[255], (Rgba{0x11, 0x11, 0x11, 255}));
  const VoxImport knight = read_vox(kCorpus / "ephtracy_chr_knight.vox");
  EXPECT_TRUE(knight.info.has_palette);
  EXPECT_NE(knight.world.palette, default_palette());
}

TEST(Vox, PackedAnimationImportsTheFirstFrame) {
  const VoxImport rex = read_vox(kCorpus / "ephtracy_T-Rex.vox");
  EXPECT_EQ(rex.world.solid_count(), rex.info.models[0].voxel_count);
  VoxImportOptions o;
  o.frame = 3;
  const VoxImport f3 = read_vox(kCorpus / "ephtracy_T-Rex.vox", o);
  EXPECT_EQ(f3.world.solid_count(), f3.info.models[3].voxel_count);
  o.frame = 8;
  EXPECT_THROW(read_vox(kCorpus / "ephtracy_T-Rex.vox", o), InvalidArgument);
}

TEST(Vox, TeardownCompressedModelsAreSupported) {
  // TDCZ: zlib-compressed dense models. The total (10864 solid voxels) was counted with Python's
  // zlib, independently of this reader; the extent is the corpus README's.
  const VoxImport in = read_vox(kCorpus / "vengi_teardown.vox");
  ASSERT_EQ(in.info.models.size(), 8u);
  std::int64_t stored = 0;
  for (const auto& m : in.info.models) {
    EXPECT_TRUE(m.compressed);
    stored += m.voxel_count;
  }
  EXPECT_EQ(stored, 10864);
  Box3i box{{0, 0, 0}, {0, 0, 0}};
  for (const auto& inst : in.info.instances) box = box.unite(inst.world_box);
  EXPECT_EQ(box.size(), (Vec3i{34, 57, 24}));
  EXPECT_GT(in.world.solid_count(), 9056);  // at least the largest model is fully placed
}

TEST(Vox, BadMagicIsRejectedWithFileAndOffset) {
  for (const char* name : {"dotvox_not_a.vox", "vengi_slab6_vox_test.vox"}) {
    try {
      read_vox(kCorpus / name);
      FAIL() << name << " was accepted";
    } catch (const FormatError& e) {
      EXPECT_EQ(e.offset(), 0u);
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("magic"), std::string::npos) << e.what();
    }
  }
}

TEST(Vox, EveryTruncationIsAFormatError) {
  for (const char* name : {"ephtracy_chr_knight.vox", "jgraef_test_materials.vox", "vengi_robo.vox",
                           "vengi_teardown.vox"}) {
    const auto bytes = read_file(kCorpus / name);
    for (std::size_t n = 0; n < bytes.size(); n += (n < 2000 ? 1 : 97)) {
      EXPECT_THROW(parse_vox(std::span(bytes.data(), n), name), FormatError)
          << name << " cut at " << n;
    }
  }
}

TEST(Vox, CorruptedBytesNeverCrash) {
  // Flip bytes at every position of a small real file: each result either parses or throws
  // FormatError; anything else (a crash, another exception) fails the test. Run under ASan too.
  const auto bytes = read_file(kCorpus / "vengi_robo.vox");
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    for (std::uint8_t v : {std::uint8_t{0xFF}, std::uint8_t{0x80}, std::uint8_t{0x00}}) {
      auto b = bytes;
      b[i] = v;
      try {
        parse_vox(b, "mutated");
      } catch (const FormatError&) {
      }
    }
  }
}

TEST(Vox, ChunkOverrunningItsParentIsRejected) {
  Bytes f = vox_file({size_chunk(2, 2, 2), xyzi_chunk({{0, 0, 0, 1}})});
  // XYZI content size is at offset 8 (header) + 12 (MAIN header) + 24 (SIZE) + 4.
  f[8 + 12 + 24 + 4] = 0xF0;
  try {
    parse_vox(f, "overrun.vox");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_EQ(e.offset(), 44u);
    EXPECT_NE(std::string(e.what()).find("overrun.vox"), std::string::npos);
  }
}

TEST(Vox, VoxelOutsideSizeIsRejected) {
  const Bytes f = vox_file({size_chunk(2, 2, 2), xyzi_chunk({{0, 0, 0, 1}, {1, 2, 1, 1}})});
  try {
    parse_vox(f, "outside.vox");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("outside the model size"), std::string::npos) << e.what();
    EXPECT_EQ(e.offset(), 8u + 12 + 24 + 12 + 4 + 4);  // the second voxel
  }
}

TEST(Vox, AbsurdSizesAndCountsAreRejectedBeforeAllocating) {
  EXPECT_THROW(parse_vox(vox_file({size_chunk(100000, 1, 1), xyzi_chunk({})}), "a"), FormatError);
  EXPECT_THROW(parse_vox(vox_file({size_chunk(0, 1, 1), xyzi_chunk({})}), "a"), FormatError);
  EXPECT_THROW(parse_vox(vox_file({size_chunk(-5, 1, 1), xyzi_chunk({})}), "a"), FormatError);
  Bytes count;
  put32(count, 0x7FFFFFFF);  // two billion voxels in a 4-byte chunk
  EXPECT_THROW(parse_vox(vox_file({size_chunk(4, 4, 4), chunk("XYZI", count)}), "a"), FormatError);
  Bytes dict;
  put32(dict, 0);
  put32(dict, 0x40000000);  // dictionary of a billion entries
  EXPECT_THROW(parse_vox(vox_file({chunk("nGRP", dict)}), "a"), FormatError);
  EXPECT_THROW(parse_vox(vox_file({xyzi_chunk({{0, 0, 0, 1}})}), "a"), FormatError);  // no SIZE
}

TEST(Vox, SceneGraphCyclesAndDanglingReferencesAreRejected) {
  // 0 -> group 1 -> transform 2 -> group 1 ...
  const Bytes cycle =
      vox_file({size_chunk(1, 1, 1), xyzi_chunk({{0, 0, 0, 1}}), transform_chunk(0, 1, -1, {}),
                group_chunk(1, {2}), transform_chunk(2, 1, -1, {})});
  EXPECT_THROW(parse_vox(cycle, "cycle.vox"), FormatError);
  const Bytes dangling =
      vox_file({size_chunk(1, 1, 1), xyzi_chunk({{0, 0, 0, 1}}), transform_chunk(0, 7, -1, {})});
  EXPECT_THROW(parse_vox(dangling, "dangling.vox"), FormatError);
  const Bytes bad_model = vox_file({size_chunk(1, 1, 1), xyzi_chunk({{0, 0, 0, 1}}),
                                    transform_chunk(0, 1, -1, {}), shape_chunk(1, 5)});
  EXPECT_THROW(parse_vox(bad_model, "model.vox"), FormatError);
  // A doubling DAG 40 levels deep would visit 2^40 nodes: the walk budget stops it.
  std::vector<Bytes> parts{size_chunk(1, 1, 1), xyzi_chunk({{0, 0, 0, 1}}),
                           transform_chunk(0, 1, -1, {})};
  for (int level = 1; level <= 40; ++level)
    parts.push_back(group_chunk(level, {level + 1, level + 1}));
  parts.push_back(group_chunk(41, {}));
  EXPECT_THROW(parse_vox(vox_file(parts), "dag.vox"), FormatError);
  const Bytes bad_rotation =
      vox_file({size_chunk(1, 1, 1), xyzi_chunk({{0, 0, 0, 1}}),
                transform_chunk(0, 1, -1, {{"_r", "5"}}), shape_chunk(1, 0)});
  EXPECT_THROW(parse_vox(bad_rotation, "rot.vox"), FormatError);  // rows 0 and 1 both pick column 1
}

TEST(Vox, TranslationRotationAndHiddenLayers) {
  // A 3x2x1 model with voxels marking its corners.
  const Bytes model_size = size_chunk(3, 2, 1);
  const Bytes model = xyzi_chunk({{0, 0, 0, 1}, {2, 0, 0, 2}, {0, 1, 0, 3}});
  // Instance A at translation (10, 20, 30), no rotation: voxel v lands on T + v - floor(size/2)
  // = (10,20,30) + v - (1,1,0).
  // Instance B rotated 90 degrees about z (rows: x' = -y, y' = x; byte: row0 column 1,
  // row1 column 0, row0 negative = 1 | 0 << 2 | 1 << 4 = 17), at (0, 0, 0).
  // Instance C on a hidden layer.
  const Bytes f =
      vox_file({model_size, model, transform_chunk(0, 1, -1, {}), group_chunk(1, {2, 4, 6}),
                transform_chunk(2, 3, 0, {{"_t", "10 20 30"}}, {{"_name", "A"}}), shape_chunk(3, 0),
                transform_chunk(4, 5, 0, {{"_r", "17"}}), shape_chunk(5, 0),
                transform_chunk(6, 7, 1, {{"_t", "-50 0 0"}}), shape_chunk(7, 0),
                layer_chunk(0, false), layer_chunk(1, true)});
  const VoxImport in = parse_vox(f, "scene.vox");
  ASSERT_EQ(in.info.instances.size(), 3u);
  EXPECT_EQ(in.info.instances[0].name, "A");
  EXPECT_TRUE(in.info.instances[2].hidden);
  const Grid<std::uint8_t>& g = in.world.voxels;
  EXPECT_EQ(g.get({9, 19, 30}), 1);
  EXPECT_EQ(g.get({11, 19, 30}), 2);
  EXPECT_EQ(g.get({9, 20, 30}), 3);
  // Rotated: centre offsets q = 2(v - pivot) + 1; v=(0,0,0) -> q=(-1,-1,1) -> Rq=(1,-1,1) ->
  // (0,-1,0).
  EXPECT_EQ(g.get({0, -1, 0}), 1);
  // v=(2,0,0) -> q=(3,-1,1) -> Rq=(1,3,1) -> floor/2 = (0,1,0).
  EXPECT_EQ(g.get({0, 1, 0}), 2);
  // v=(0,1,0) -> q=(-1,1,1) -> Rq=(-1,-1,1) -> (-1,-1,0).
  EXPECT_EQ(g.get({-1, -1, 0}), 3);
  EXPECT_EQ(in.world.solid_count(), 6);  // the hidden instance is not imported
  VoxImportOptions all;
  all.include_hidden = true;
  EXPECT_EQ(parse_vox(f, "scene.vox", all).world.solid_count(), 9);
}

TEST(Vox, ExportSplitsLargeWorldsIntoModelsOfAtMost256) {
  World w;
  w.voxels.set({-300, 0, 0}, 1);
  w.voxels.set({400, 5, 600}, 2);
  w.voxels.fill({{0, 0, 0}, {300, 4, 4}}, 3);
  const VoxImport back = parse_vox(encode_vox(w), "split.vox");
  for (const auto& m : back.info.models) {
    EXPECT_LE(m.size.x, 256);
    EXPECT_LE(m.size.y, 256);
    EXPECT_LE(m.size.z, 256);
  }
  EXPECT_GE(back.info.models.size(), 4u);
  EXPECT_EQ(back.world.solid_count(), w.solid_count());
  EXPECT_EQ(back.world.voxels.get({-300, 0, 0}), 1);
  EXPECT_EQ(back.world.voxels.get({400, 5, 600}), 2);
  EXPECT_EQ(back.world.voxels.get({299, 3, 3}), 3);
  // An empty world still makes a valid file.
  EXPECT_EQ(parse_vox(encode_vox(World{}), "empty.vox").world.solid_count(), 0);
}

TEST(Vox, GoldenBytesOfATinyWorld) {
  // Two voxels: material 5 at (0,0,0) and 7 at (1,0,2). The expected file is written out chunk
  // by chunk here, following the published format, independently of the encoder.
  World w;
  w.palette[5] = {1, 2, 3, 4};
  w.voxels.set({0, 0, 0}, 5);
  w.voxels.set({1, 0, 2}, 7);
  std::vector<Bytes> parts{size_chunk(2, 1, 3),
                           xyzi_chunk({{0, 0, 0, 5}, {1, 0, 2, 7}}),
                           transform_chunk(0, 1, -1, {}),
                           group_chunk(1, {2}),
                           transform_chunk(2, 3, 0, {{"_t", "1 0 1"}}),
                           shape_chunk(3, 0),
                           layer_chunk(0, false)};
  Bytes rgba;
  for (int i = 0; i < 256; ++i) {
    const Rgba c = i < 255 ? w.palette[i + 1] : Rgba{};
    rgba.insert(rgba.end(), {c.r, c.g, c.b, c.a});
  }
  parts.push_back(chunk("RGBA", rgba));
  const Bytes expected = vox_file(parts, 200);
  const Bytes got = encode_vox(w);
  EXPECT_EQ(got, expected);
}
