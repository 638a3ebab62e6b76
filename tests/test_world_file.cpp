// The durable world file: exact round trips (world and fields), every corruption caught, future
// versions refused, and a save killed at a random moment never damaging the previous file.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <random>
#include <thread>

#include "voxfield/scene.h"
#include "voxfield/vectors.h"
#include "voxfield/world_file.h"
#include "world_file_bytes.h"
#include "world_voxels.h"

#include <zlib.h>

using namespace voxfield;
namespace fs = std::filesystem;

namespace {

fs::path temp_dir() {
  const fs::path d = fs::temp_directory_path() / ("voxfield_vfw_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

}  // namespace

TEST(WorldFile, RoundTripsWorldsAndFieldsExactly) {
  SceneOptions o;
  o.size = {70, 45, 33};
  World w = make_terrain(o);
  w.palette[200] = {1, 2, 3, 4};
  w.voxels.fill({{0, 0, 0}, {32, 32, 32}}, 7);  // a uniform chunk
  DistanceOptions fo;
  fo.metric = Metric::kEuclidean;
  fo.signed_distance = true;
  fo.max_distance = 9;
  fo.storage = Storage::kU16;
  fo.nearest_sites = true;
  const DistanceField f1 = compute_distance_field(w, fo);
  DistanceOptions fo2;
  const DistanceField f2 = compute_distance_field(w, fo2);
  const auto bytes = encode_world_file(w, {&f1, &f2});
  const WorldFile back = parse_world_file(bytes, "rt.vfw");
  EXPECT_EQ(back.version, 1u);  // the identity frame: the format before frames, for older readers
  EXPECT_EQ(back.world.palette, w.palette);
  EXPECT_EQ(back.world.voxels.bounds(), w.voxels.bounds());
  EXPECT_EQ(test::dense_voxels(back.world, *w.voxels.bounds()),
            test::dense_voxels(w, *w.voxels.bounds()));
  EXPECT_EQ(back.world.voxels.memory().uniform_chunks, w.voxels.memory().uniform_chunks);
  ASSERT_EQ(back.fields.size(), 2u);
  const Box3i box = *w.voxels.bounds();
  const auto& a = std::get<Grid<std::uint16_t>>(back.fields[0].values);
  const auto& b = std::get<Grid<std::uint16_t>>(f1.values);
  std::vector<std::uint16_t> va(static_cast<std::size_t>(box.volume())), vb(va.size());
  a.copy_to_dense(box, va.data());
  b.copy_to_dense(box, vb.data());
  EXPECT_EQ(va, vb);
  EXPECT_EQ(back.fields[0].encoding.bias, f1.encoding.bias);
  EXPECT_EQ(back.fields[0].options.max_distance, 9);
  ASSERT_TRUE(back.fields[0].sites.has_value());
  EXPECT_EQ(back.fields[0].sites->get({10, 10, 10}), f1.sites->get({10, 10, 10}));
  EXPECT_EQ(back.fields[1].distance({5, 40, 30}), f2.distance({5, 40, 30}));
  // Uniform chunks are stored as a value: a solid 64^3 block (8 chunks) costs a few bytes more
  // than an empty world.
  World solid(32, Box3i::from_size({64, 64, 64}));
  const std::size_t empty_bytes = encode_world_file(solid).size();
  solid.voxels.fill(Box3i::from_size({64, 64, 64}), 3);
  EXPECT_LE(encode_world_file(solid).size(), empty_bytes + 8 * 14);
}

TEST(WorldFile, CorruptionTruncationAndFutureVersionsAreRejected) {
  SceneOptions o;
  o.size = {40, 40, 40};
  const World w = make_spheres(o);
  const auto good = encode_world_file(w);
  std::mt19937 rng(3);
  for (int i = 0; i < 300; ++i) {
    auto bad = good;
    const std::size_t at = rng() % bad.size();
    bad[at] ^= static_cast<std::uint8_t>(1 + rng() % 255);
    EXPECT_THROW(parse_world_file(bad, "flip.vfw"), FormatError) << "byte " << at;
  }
  for (std::size_t n = 0; n < good.size(); n += 1 + good.size() / 500) {
    EXPECT_THROW(parse_world_file(std::span(good.data(), n), "cut.vfw"), FormatError) << n;
  }
  // A future version: patch the version and fix the header checksum so only the version is wrong.
  auto future = good;
  future[8] = static_cast<std::uint8_t>(kWorldFileVersion + 1);
  const std::uint32_t c =
      static_cast<std::uint32_t>(crc32(crc32(0, nullptr, 0), future.data(), 16));
  std::memcpy(future.data() + 16, &c, 4);
  try {
    parse_world_file(future, "future.vfw");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("newer voxfield"), std::string::npos) << e.what();
  }
}

TEST(WorldFile, FramesRoundTripAndBadOnesAreRefused) {
  SceneOptions o;
  o.size = {30, 20, 25};
  World w = make_spheres(o);
  w.frame.origin_world = {-12.5, 3.25, 1e3};
  w.frame.voxel_size_world = {0.1, 0.1, 0.25};
  w.frame.rotation = VectorVolume::rotation_about(30, {1, 2, 3});
  const DistanceField f = compute_distance_field(w, {});
  EXPECT_EQ(f.frame, w.frame);  // a field carries its world's frame
  const auto bytes = encode_world_file(w, {&f});
  const WorldFile back = parse_world_file(bytes, "framed.vfw");
  EXPECT_EQ(back.version, 2u);
  EXPECT_EQ(back.world.frame, w.frame);  // bit for bit: stored as doubles
  ASSERT_EQ(back.fields.size(), 1u);
  EXPECT_EQ(back.fields[0].frame, w.frame);
  EXPECT_EQ(test::dense_voxels(back.world, *w.voxels.bounds()),
            test::dense_voxels(w, *w.voxels.bounds()));
  // The frame section follows the world's: 12 bytes of section head, 15 doubles.
  std::uint64_t world_bytes = 0;
  std::memcpy(&world_bytes, bytes.data() + 24, 8);
  const std::size_t frame_at = 20 + 12 + world_bytes + 4;
  std::uint32_t kind = 0;
  std::memcpy(&kind, bytes.data() + frame_at, 4);
  ASSERT_EQ(kind, 3u);
  const std::size_t values_at = frame_at + 12;
  auto patched = [&](int value_index, double v) {
    auto bad = bytes;
    std::memcpy(bad.data() + values_at + 8 * value_index, &v, 8);
    test::fix_world_file_checksums(bad);
    return bad;
  };
  const std::pair<int, double> bad_values[] = {
      {0, std::nan("")},  // origin x
      {4, 0.0},           // voxel size y
      {5, -0.25},         // voxel size z
      {6, 2.0},           // a rotation entry: rows no longer unit
  };
  for (const auto& [i, v] : bad_values) {
    try {
      parse_world_file(patched(i, v), "bad-frame.vfw");
      FAIL() << "value " << i << " = " << v << " was accepted";
    } catch (const FormatError& e) {
      EXPECT_NE(std::string(e.what()).find("bad-frame.vfw"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("frame"), std::string::npos) << e.what();
    }
  }
  // A mirror (one rotation row negated) is refused: a frame turns, it does not reflect.
  auto mirrored = bytes;
  for (int c = 0; c < 3; ++c) {
    double v = 0;
    std::memcpy(&v, mirrored.data() + values_at + 8 * (6 + c), 8);
    v = -v;
    std::memcpy(mirrored.data() + values_at + 8 * (6 + c), &v, 8);
  }
  test::fix_world_file_checksums(mirrored);
  EXPECT_THROW(parse_world_file(mirrored, "mirror.vfw"), FormatError);
  // Two frame sections: the second does not follow the world.
  auto twice = bytes;
  const std::size_t frame_end = values_at + 15 * 8 + 4;
  twice.insert(twice.begin() + static_cast<std::ptrdiff_t>(frame_end),
               bytes.begin() + static_cast<std::ptrdiff_t>(frame_at),
               bytes.begin() + static_cast<std::ptrdiff_t>(frame_end));
  std::uint32_t sections = 0;
  std::memcpy(&sections, twice.data() + 12, 4);
  ++sections;
  std::memcpy(twice.data() + 12, &sections, 4);
  test::fix_world_file_checksums(twice);
  EXPECT_THROW(parse_world_file(twice, "twice.vfw"), FormatError);
  // A frame section in a version-1 file: that version has none.
  auto old = bytes;
  old[8] = 1;
  test::fix_world_file_checksums(old);
  EXPECT_THROW(parse_world_file(old, "v1.vfw"), FormatError);
  // And a world in the identity frame is written as before frames, as version 1.
  World plain = w;
  plain.frame = {};
  EXPECT_EQ(parse_world_file(encode_world_file(plain), "plain.vfw").version, 1u);
}

TEST(WorldFile, KillingASaveNeverDamagesThePreviousFile) {
  const fs::path dir = temp_dir();
  const fs::path path = dir / "world.vfw";
  SceneOptions o;
  o.size = {192, 192, 96};  // large enough that a save takes a while
  const World a = make_terrain(o);
  o.seed = 99;
  const World b = make_terrain(o);
  const Box3i box = Box3i::from_size(o.size);
  const auto da = test::dense_voxels(a, box), db = test::dense_voxels(b, box);
  write_world_file(a, path);
  std::mt19937 rng(8);
  for (int round = 0; round < 6; ++round) {
    const pid_t child = fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      // Save alternately forever; the parent kills us mid-write.
      for (int i = 0;; ++i) write_world_file(i % 2 ? a : b, path);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20 + rng() % 200));
    kill(child, SIGKILL);
    int status = 0;
    waitpid(child, &status, 0);
    const WorldFile back = read_world_file(path);  // must parse: old or new, never a mix
    const auto d = test::dense_voxels(back.world, box);
    EXPECT_TRUE(d == da || d == db) << "round " << round;
  }
  fs::remove_all(dir);
}

// A file assembled from parts (voxfield-mpi's ranks each encode the chunks of their slab) is the
// whole world's file byte for byte, wherever the parts are cut along z, and reads back.
TEST(WorldFile, PartsAssembleIntoTheWholeFile) {
  std::mt19937 rng(23);
  for (int edge : {8, 16}) {
    for (int trial = 0; trial < 6; ++trial) {
      const Vec3i origin{static_cast<int>(rng() % 20) - 10, static_cast<int>(rng() % 20) - 10,
                         static_cast<int>(rng() % 40) - 20};
      const Box3i bounds{
          origin, origin + Vec3i{5 + static_cast<int>(rng() % 30), 4 + static_cast<int>(rng() % 30),
                                 10 + static_cast<int>(rng() % 90)}};
      World w(edge, bounds);
      w.palette[3] = {1, 2, 3, 4};
      if (trial % 3 == 1) {  // a frame: its section goes in the tail
        w.frame.origin_world = {1.5, -2, 1e-3};
        w.frame.voxel_size_world = {0.5, 0.5, 2};
      }
      for (int k = 0; k < 400; ++k) {
        const Vec3i s = bounds.size();
        w.voxels.set(
            bounds.begin + Vec3i{static_cast<int>(rng() % s.x), static_cast<int>(rng() % s.y),
                                 static_cast<int>(rng() % s.z)},
            static_cast<std::uint8_t>(1 + rng() % 5));
      }
      // A solid layer: uniform chunks among the dense ones.
      if (trial % 2)
        w.voxels.fill(bounds.intersect(
                          {bounds.begin, {bounds.end.x, bounds.end.y, bounds.begin.z + 3 * edge}}),
                      7);
      w.voxels.compact();
      const std::vector<std::uint8_t> whole = encode_world_file(w);
      // Cuts at chunk z coordinates, from below the first chunk to past the last.
      const int c0 = (bounds.begin.z - edge * 64) / edge - 64, c1 = bounds.end.z / edge + 2;
      std::vector<int> cuts{c0, c1};
      for (int i = 0; i < static_cast<int>(rng() % 4); ++i)
        cuts.push_back((bounds.begin.z >> (edge == 8 ? 3 : 4)) + static_cast<int>(rng() % 12) - 2);
      std::sort(cuts.begin(), cuts.end());
      std::vector<WorldFilePart> parts;
      std::vector<WorldFilePartSummary> summaries;
      for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
        parts.push_back(encode_world_file_part(w.voxels, cuts[i], cuts[i + 1]));
        summaries.push_back({parts.back().chunks, parts.back().records.size(), parts.back().crc});
      }
      const WorldFileFrame frame =
          encode_world_file_frame(w.palette, edge, w.voxels.bounds(), summaries, w.frame);
      std::vector<std::uint8_t> assembled = frame.head;
      for (const WorldFilePart& p : parts)
        assembled.insert(assembled.end(), p.records.begin(), p.records.end());
      assembled.insert(assembled.end(), frame.tail.begin(), frame.tail.end());
      ASSERT_EQ(assembled, whole) << "edge " << edge << " trial " << trial << ", " << parts.size()
                                  << " parts";
      const WorldFile back = parse_world_file(assembled, "assembled.vfw");
      EXPECT_EQ(test::dense_voxels(back.world, bounds), test::dense_voxels(w, bounds));
      EXPECT_EQ(back.world.frame, w.frame);
    }
  }
}

// Where a world's content can lie, from its chunk records alone (voxfield-mpi bounds an unbounded
// world's domain by it before any rank decodes its slab): the union of the stored chunks' boxes
// that hold anything but air (chunk-granular, never smaller than the content), whatever a slab
// read decodes, within the grid's bounds.
TEST(WorldFile, StoredChunksBoxCoversTheContentFromTheRecordsAlone) {
  World w(8);                                    // unbounded
  w.voxels.set({3, -9, 30}, 2);                  // in chunk [0, -16, 24] .. [8, -8, 32]
  w.voxels.fill({{-16, 0, -8}, {-8, 8, 0}}, 5);  // one uniform chunk of a material
  const auto bytes = encode_world_file(w, {});
  const Box3i expect{{-16, -16, -8}, {8, 8, 32}};
  EXPECT_TRUE(expect.contains(w.voxels.content_bounds()));
  for (const auto& keep : std::vector<std::optional<std::pair<std::int32_t, std::int32_t>>>{
           std::nullopt, std::pair<std::int32_t, std::int32_t>{0, 0},
           std::pair<std::int32_t, std::int32_t>{-8, 0}}) {
    WorldFileReadOptions o;
    o.keep_z = keep;
    EXPECT_EQ(parse_world_file(bytes, "w.vfw", o).stored_chunks_box, expect);
  }
  // Within the grid's bounds when it has them; empty for a world of air.
  World bounded(8, Box3i{{0, -4, 0}, {20, 20, 36}});
  bounded.voxels.set({3, -4, 30}, 2);
  EXPECT_EQ(parse_world_file(encode_world_file(bounded, {}), "b.vfw").stored_chunks_box,
            (Box3i{{0, -4, 24}, {8, 0, 32}}));
  EXPECT_TRUE(
      parse_world_file(encode_world_file(World(8), {}), "air.vfw").stored_chunks_box.empty());
}

// A slab of a world file (voxfield-mpi's ranks): only the chunks reaching into the z range are
// decoded — equal to the whole file's there, none elsewhere — fields are skipped, the frame kept,
// the memory limit charged for the slab alone, and every checksum still checked.
TEST(WorldFile, SlabsDecodeOnlyTheirChunks) {
  const Box3i bounds{{-5, 3, -20}, {35, 33, 45}};
  World w(8, bounds);
  std::mt19937 rng(11);
  for (int k = 0; k < 3000; ++k) {
    const Vec3i s = bounds.size();
    w.voxels.set(bounds.begin + Vec3i{static_cast<int>(rng() % s.x), static_cast<int>(rng() % s.y),
                                      static_cast<int>(rng() % s.z)},
                 static_cast<std::uint8_t>(1 + rng() % 9));
  }
  w.voxels.fill({{-5, 3, 8}, {35, 33, 17}}, 4);  // uniform chunks, and ones the layer cuts
  w.frame.voxel_size_world = {0.5, 0.5, 0.5};
  const DistanceField f = compute_distance_field(w, {});
  const auto bytes = encode_world_file(w, {&f});
  const WorldFile whole = parse_world_file(bytes, "whole.vfw");
  for (const auto& [z0, z1] : std::vector<std::pair<int, int>>{
           {-20, -12}, {-3, 9}, {8, 17}, {30, 45}, {44, 100}, {0, 0}}) {
    WorldFileReadOptions o;
    o.keep_z = std::pair<std::int32_t, std::int32_t>{z0, z1};
    const WorldFile part = parse_world_file(bytes, "slab.vfw", o);
    const std::string what = "z in [" + std::to_string(z0) + ", " + std::to_string(z1) + ")";
    EXPECT_TRUE(part.fields.empty()) << what;
    EXPECT_EQ(part.world.frame, w.frame) << what;
    EXPECT_EQ(part.world.palette, w.palette) << what;
    EXPECT_EQ(part.world.voxels.bounds(), w.voxels.bounds()) << what;
    for (const Vec3i c : part.world.voxels.chunk_coords()) {
      const Box3i b = part.world.voxels.chunk_box(c);
      EXPECT_TRUE(b.begin.z < z1 && z0 < b.end.z) << what << ": chunk " << to_string(c);
    }
    const Box3i slab = bounds.intersect(
        {{bounds.begin.x, bounds.begin.y, z0}, {bounds.end.x, bounds.end.y, std::max(z0, z1)}});
    if (!slab.empty()) {
      EXPECT_EQ(test::dense_voxels(part.world, slab), test::dense_voxels(whole.world, slab))
          << what;
    } else {
      EXPECT_EQ(part.world.voxels.chunk_count(), 0u) << what;
    }
  }
  // The limit counts the slab: one that refuses the whole world admits a thin slab.
  WorldFileReadOptions tight;
  tight.memory_limit_bytes = 40 * (8 * 8 * 8 + 96);
  EXPECT_THROW(parse_world_file(bytes, "tight.vfw", tight), ResourceLimitError);
  tight.keep_z = std::pair<std::int32_t, std::int32_t>{-20, -16};
  EXPECT_NO_THROW(parse_world_file(bytes, "tight.vfw", tight));
  // A corrupted byte is still found where the slab decodes nothing (here the field section, which
  // it skips): every section's checksum is checked.
  auto bad = bytes;
  bad[bad.size() / 2] ^= 0x40;
  WorldFileReadOptions o;
  o.keep_z = std::pair<std::int32_t, std::int32_t>{-20, -16};
  EXPECT_THROW(parse_world_file(bad, "bad.vfw", o), FormatError);
}
