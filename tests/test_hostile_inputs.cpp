// Hostile inputs beyond the file parsers: coordinates at the edge of the supported range, sizes
// that would overflow, the memory limit itself, edit scripts, and loading by file type.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "error_text.h"
#include "voxfield/edit_script.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/world_file.h"
#include "voxfield/world_io.h"

using namespace voxfield;
using voxfield::test::error_of;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir(const char* name) {
  const fs::path d = fs::temp_directory_path() /
                     ("voxfield_hostile_" + std::string(name) + "_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(CoordinateRange, SizesAndVolumesNeverOverflow) {
  const Box3i all{Vec3i::splat(INT32_MIN), Vec3i::splat(INT32_MAX)};
  EXPECT_EQ(all.extent(0), std::int64_t{UINT32_MAX});
  EXPECT_EQ(all.size().x, INT32_MAX);  // saturates instead of wrapping
  EXPECT_EQ(all.volume(), INT64_MAX);
  EXPECT_FALSE(all.in_range());
  EXPECT_EQ(kCoordRange.size().x, 1 << 30);  // exact inside the range
  EXPECT_TRUE(kCoordRange.in_range());
  EXPECT_EQ((Box3i{{0, 0, 0}, {1 << 21, 1 << 21, 1 << 21}}.volume()),
            INT64_MAX);  // 2^63 does not fit
  EXPECT_EQ((Box3i{{0, 0, 0}, {1 << 20, 1 << 20, 1 << 20}}.volume()), std::int64_t{1} << 60);
}

TEST(CoordinateRange, GridsRefuseVoxelsChunksAndBoundsOutside) {
  Grid<std::uint8_t> g(8);
  EXPECT_NO_THROW(g.set({kCoordLimit - 1, -kCoordLimit, 0}, 1));
  EXPECT_THROW(g.set({kCoordLimit, 0, 0}, 1), InvalidArgument);
  EXPECT_THROW(g.set({0, -kCoordLimit - 1, 0}, 1), InvalidArgument);
  EXPECT_EQ(g.count_non_background(), 1);
  EXPECT_THROW(g.fill({{kCoordLimit - 4, 0, 0}, {kCoordLimit + 4, 1, 1}}, 2), InvalidArgument);
  EXPECT_TRUE(g.chunk_in_range({(kCoordLimit >> 3) - 1, 0, 0}));
  EXPECT_FALSE(g.chunk_in_range({kCoordLimit >> 3, 0, 0}));
  EXPECT_FALSE(g.chunk_in_range({INT32_MIN, 0, 0}));
  EXPECT_THROW(g.edit_chunk({INT32_MIN, 0, 0}, [](auto&) {}), InvalidArgument);
  EXPECT_THROW(Grid<std::uint8_t>(8, 0, Box3i{{0, 0, 0}, {kCoordLimit + 1, 1, 1}}),
               InvalidArgument);
}

TEST(CoordinateRange, FieldsOverHugeDomainsAreRefusedBeforeAllocating) {
  // Two voxels 2^28 apart: a dense field over their box would need 2^28 x 4 bytes = 1 GiB.
  World w(32);
  w.voxels.set({0, 0, 0}, 1);
  w.voxels.set({1 << 28, 0, 0}, 1);
  set_default_memory_limit(256u << 20);
  const std::string msg = error_of([&] { (void)compute_distance_field(w, DistanceOptions{}); });
  set_default_memory_limit(0);
  EXPECT_NE(msg.find("memory limit of 256.0 MiB"), std::string::npos) << msg;
}

TEST(MemoryLimit, SizesParseAndRefusalsSayWhatAndWhy) {
  EXPECT_EQ(parse_byte_size("123"), 123u);
  EXPECT_EQ(parse_byte_size("64k"), 64u << 10);
  EXPECT_EQ(parse_byte_size("8G"), std::uint64_t{8} << 30);
  EXPECT_EQ(parse_byte_size("2GiB"), std::uint64_t{2} << 30);
  EXPECT_THROW(parse_byte_size("8X"), InvalidArgument);
  EXPECT_EQ(parse_byte_size(" 8 GiB "), std::uint64_t{8} << 30);
  EXPECT_THROW(parse_byte_size("0"), InvalidArgument);
  EXPECT_THROW(parse_byte_size("0 GiB"), InvalidArgument);
  // A cache's size may be 0 (off), in any unit.
  EXPECT_EQ(parse_byte_size("0", "cache", ZeroSize::kAllowed), 0u);
  EXPECT_EQ(parse_byte_size("0 GiB", "cache", ZeroSize::kAllowed), 0u);
  EXPECT_EQ(parse_byte_size("64M", "cache", ZeroSize::kAllowed), std::uint64_t{64} << 20);
  EXPECT_THROW(parse_byte_size("none", "cache", ZeroSize::kAllowed), InvalidArgument);
  EXPECT_THROW(parse_byte_size("99999999999999999999"), InvalidArgument);
  EXPECT_THROW(parse_byte_size("17179869184T"), InvalidArgument);  // 2^64 bytes
  EXPECT_EQ(format_bytes(1536), "1.5 KiB");
  EXPECT_GT(physical_memory_bytes(), 0u);
  EXPECT_EQ(default_memory_limit() > 0, true);
  set_default_memory_limit(1000);
  EXPECT_EQ(default_memory_limit(), 1000u);
  set_default_memory_limit(0);
  EXPECT_NE(default_memory_limit(), 1000u);
  const std::string msg =
      error_of([] { require_memory(3u << 30, 1u << 30, "x.vox", "its chunks"); });
  EXPECT_EQ(msg,
            "x.vox: its chunks needs 3.0 GiB, more than the memory limit of 1.0 GiB "
            "(raise it with --memory-limit or VOXFIELD_MEMORY_LIMIT)");
}

TEST(EditScripts, SemanticsAreCheckedAtParseTimeWithTheLine) {
  auto parse = [](const std::string& text) {
    EditScriptOptions o;
    o.load_stamps = false;
    return parse_edit_script(
        std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()), "e.jsonl", o);
  };
  const std::string ok =
      R"({"op":"place","shape":"sphere","center":[1,2,3],"radius":2,"material":4})";
  ASSERT_EQ(parse(ok + "\n\n" + ok).size(), 2u);
  const struct {
    const char* line;
    const char* says;
  } bad[] = {
      {R"({"op":"place","shape":"sphere","center":[1,2,3],"radius":-1})", "\"radius\" is -1"},
      {R"({"op":"place","shape":"box","min":[5,0,0],"max":[4,3,3]})", "exceeds \"max\""},
      {R"({"op":"place","shape":"rotated-box","center":[0,0,0],"half_extent":[1,-2,1]})",
       "\"half_extent\" is -2"},
      {R"({"op":"paint","shape":"sphere","center":[0,0,0],"radius":1,"material":0})",
       "\"material\" 0 is air"},
      {R"({"op":"place","shape":"sphere","center":[0,0,0],"radius":1,"material":1.5})",
       "must be an integer"},
      {R"({"op":"place","shape":"sphere","center":[2147483648,0,0],"radius":1})",
       "\"center\" is 2147483648"},
      {R"({"op":"place","shape":"sphere","center":[1e300,0,0],"radius":1})",
       "\"center\" is 1e+300"},
      {R"({"op":"place","shape":"sphere","centre":[0,0,0],"radius":1})", "unknown key \"centre\""},
      {R"({"op":"place","shape":"capsule","a":[0,0,0],"b":[1,1,1]})", "missing \"radius\""},
      {R"({"op":"melt","shape":"sphere"})", "unknown op"},
      {R"({"op":"place","shape":"sphere","center":[0,0,0],"radius":1)", "not valid JSON"},
      // fuzz_edit_script's first finding: a number beyond double's range escaped as nlohmann's
      // out_of_range instead of a voxfield error.
      {R"({"op":"place","shape":"sphere","center":[777777777777777777777777e000000000000006714515034139233898,0,0],"radius":1})",
       "number overflow"},
  };
  for (const auto& b : bad) {
    const std::string msg = error_of([&] { parse(ok + "\n" + b.line + "\n"); });
    EXPECT_NE(msg.find("e.jsonl: at byte " + std::to_string(ok.size() + 1) + ": line 2: "),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find(b.says), std::string::npos) << b.line << " -> " << msg;
  }
  const fs::path dir = temp_dir("script");
  EXPECT_THROW(read_edit_script(dir),
               IoError);  // a directory is not a script (it used to be "0 edits")
  fs::remove_all(dir);
}

TEST(LoadWorld, MagicIsCheckedBeforeTheFileIsRead) {
  const fs::path dir = temp_dir("magic");
  {
    std::ofstream f(dir / "big.vox", std::ios::binary);
    f << "NOTAVOX!";
    f.seekp((64 << 20) - 1);
    f.put('\0');  // 64 MiB, sparse on disk
  }
  LoadOptions o;
  o.memory_limit_bytes = 16u << 20;  // below the file's size: reading it whole would be refused
  const std::string msg = error_of([&] { load_world(dir / "big.vox", o); });
  EXPECT_NE(msg.find("not a MagicaVoxel file"), std::string::npos) << msg;
  fs::remove_all(dir);
}

TEST(LoadWorld, ReChunkingFollowsTheContentNotItsBox) {
  // Two chunks 2^28 voxels apart saved at edge 16; loading at edge 32 used to copy their box
  // densely.
  World w(16);
  w.voxels.set({3, 4, 5}, 7);
  w.voxels.set({1 << 28, 9, 2}, 9);
  const fs::path dir = temp_dir("rechunk");
  write_world_file(w, dir / "far.vfw");
  LoadOptions o;
  o.chunk_edge = 32;
  o.memory_limit_bytes = 64u << 20;
  const LoadedWorld in = load_world(dir / "far.vfw", o);
  EXPECT_EQ(in.world.voxels.chunk_edge(), 32);
  EXPECT_EQ(in.world.voxels.get({3, 4, 5}), 7);
  EXPECT_EQ(in.world.voxels.get({1 << 28, 9, 2}), 9);
  EXPECT_EQ(in.world.solid_count(), 2);
  EXPECT_EQ(in.world.voxels.chunk_count(), 2u);
  EXPECT_EQ(in.extent.size().x, (1 << 28) - 3 + 1);  // x from 3 to 2^28
  fs::remove_all(dir);
}

TEST(LoadWorld, ReChunkingIsCountedAgainstTheLimit) {
  // 200 one-voxel chunks of edge 8, 32 voxels apart (a few KB on disk): at edge 128 they make 50
  // dense chunks of 2 MiB.
  World w(8);
  for (int i = 0; i < 200; ++i) w.voxels.set({32 * i, 0, 0}, 1);
  const fs::path dir = temp_dir("rechunk_limit");
  write_world_file(w, dir / "sparse.vfw");
  LoadOptions o;
  o.chunk_edge = 128;
  o.memory_limit_bytes = 32u << 20;
  const std::string msg = error_of([&] { load_world(dir / "sparse.vfw", o); });
  EXPECT_NE(msg.find("chunks of 128^3"), std::string::npos) << msg;
  o.memory_limit_bytes = 256u << 20;
  EXPECT_EQ(load_world(dir / "sparse.vfw", o).world.voxels.chunk_count(), 50u);
  fs::remove_all(dir);
}
