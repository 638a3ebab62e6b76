// Hostile files: each crash class and memory amplification the adversarial probe found (issue
// 14), rebuilt in code as a small input, must be refused with a message naming the file and the
// cause, never crash, and never allocate past the memory limit.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cstring>
#include <string>

#include "error_text.h"
#include "vox_builder.h"
#include "voxfield/limits.h"
#include "voxfield/npy.h"
#include "voxfield/vox.h"
#include "voxfield/world_file.h"
#include "world_file_bytes.h"

using namespace voxfield;
using namespace voxfield::test;

namespace {

constexpr std::uint64_t kMiB = std::uint64_t{1} << 20;

// An .npy file with the given header dict and data bytes (header padded as NumPy pads it).
Bytes npy(std::string header, const Bytes& data) {
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  Bytes b{0x93, 'N', 'U', 'M', 'P', 'Y', 1, 0};
  b.push_back(static_cast<std::uint8_t>(header.size() & 0xFF));
  b.push_back(static_cast<std::uint8_t>(header.size() >> 8));
  b.insert(b.end(), header.begin(), header.end());
  b.insert(b.end(), data.begin(), data.end());
  return b;
}

}  // namespace

// Class 1: a shape whose product wraps past 2^64 used to pass the size check and overrun the
// reorder.
TEST(HostileNpy, ShapeProductsNeverWrap) {
  // 2^22 x 2^21 x 2^21 = 2^64 exactly: wraps to 0 in 64 bits, which used to pass the size check.
  const std::string wraps =
      "{'descr': '|u1', 'fortran_order': False, 'shape': (4194304, 2097152, 2097152), }";
  EXPECT_NE(
      error_of([&] { parse_npy(npy(wraps, Bytes(64, 1)), "wrap.npy"); }).find("more than 2^64"),
      std::string::npos);
  // A dimension beyond the coordinate range is refused on its own.
  const std::string wide =
      "{'descr': '|u1', 'fortran_order': False, 'shape': (1073741824, 1, 1), }";
  EXPECT_NE(
      error_of([&] { parse_npy(npy(wide, Bytes(64, 1)), "wide.npy"); }).find("outside 1..2^29"),
      std::string::npos);
  // Every dimension in range, the product 2^87 bytes: refused as data the file does not hold.
  const std::string big =
      "{'descr': '<f8', 'fortran_order': False, 'shape': (536870912, 536870912, 536870912), }";
  const std::string msg = error_of([&] { parse_npy(npy(big, Bytes(64, 1)), "big.npy"); });
  EXPECT_NE(msg.find("big.npy"), std::string::npos) << msg;
  EXPECT_NE(msg.find("more than 2^64"), std::string::npos) << msg;
  // A product that fits but passes the memory limit: ResourceLimitError before allocating.
  const std::string fits = "{'descr': '|u1', 'fortran_order': True, 'shape': (1024, 1024, 64), }";
  NpyReadOptions tight;
  tight.memory_limit_bytes = 16 * kMiB;
  EXPECT_THROW(parse_npy(npy(fits, Bytes(std::size_t{1024} * 1024 * 64, 0)), "fits.npy", tight),
               ResourceLimitError);
}

TEST(HostileNpy, DeliberateAcceptancesAndRefusals) {
  // int64 (NumPy's default integer) is read.
  Bytes d(8 * 8, 0);
  d[8] = 3;  // element 1 = 3
  const NpyVolume v =
      parse_npy(npy("{'descr': '<i8', 'fortran_order': True, 'shape': (2, 2, 2), }", d), "i8.npy");
  EXPECT_EQ(v.dtype, DType::kInt64);
  EXPECT_EQ(v.value(1), 3.0);
  // A key given twice, and bytes after the data, are refused.
  EXPECT_NE(
      error_of([] {
        parse_npy(
            npy("{'descr': '|u1', 'descr': '|u1', 'fortran_order': True, 'shape': (1, 1, 1), }",
                Bytes(1, 0)),
            "dup.npy");
      }).find("given twice"),
      std::string::npos);
  EXPECT_NE(error_of([] {
              parse_npy(
                  npy("{'descr': '|u1', 'fortran_order': True, 'shape': (1, 1, 1), }", Bytes(5, 0)),
                  "t.npy");
            }).find("4 bytes after the array data"),
            std::string::npos);
}

TEST(HostileNpy, ValueErrorsNameTheElementAndItsByteOffset) {
  // C order, shape (2, 3, 4) of float32: element a[1, 2, 3] is the last one, at file index 23.
  Bytes d(24 * 4, 0);
  const float bad = 1.5f;
  std::memcpy(d.data() + 23 * 4, &bad, 4);
  const Bytes file = npy("{'descr': '<f4', 'fortran_order': False, 'shape': (2, 3, 4), }", d);
  const NpyVolume v = parse_npy(file, "vals.npy");
  const std::string msg = error_of([&] { world_from_npy(v, "vals.npy"); });
  EXPECT_NE(msg.find("a[1, 2, 3]"), std::string::npos) << msg;
  EXPECT_NE(msg.find("holds 1.5"), std::string::npos) << msg;
  EXPECT_NE(msg.find("at byte " + std::to_string(file.size() - 4)), std::string::npos) << msg;
}

// Class 2: two legal one-voxel instances at -2^30 and +2^30 made a world 2^31 + 1 wide.
TEST(HostileVox, InstancesOutsideTheCoordinateRangeAreRefused) {
  auto scene = [](int a, int b) {
    return vox_file(
        {size_chunk(1, 1, 1), xyzi_chunk({{0, 0, 0, 1}}), transform_chunk(0, 1, -1, {}),
         group_chunk(1, {2, 4}), transform_chunk(2, 3, 0, {{"_t", std::to_string(a) + " 0 0"}}),
         shape_chunk(3, 0), transform_chunk(4, 5, 0, {{"_t", std::to_string(b) + " 0 0"}}),
         shape_chunk(5, 0)});
  };
  const std::string msg = error_of([&] { parse_vox(scene(-(1 << 30), 1 << 30), "far.vox"); });
  EXPECT_NE(msg.find("far.vox"), std::string::npos) << msg;
  EXPECT_NE(msg.find("outside the supported coordinate range"), std::string::npos) << msg;
  // At +-2^28 both lie in range: the world is 2^29 + 1 wide, and its size reads as such.
  const VoxImport in = parse_vox(scene(-(1 << 28), 1 << 28), "wide.vox");
  const Box3i b = in.world.voxels.content_bounds();
  EXPECT_EQ(b.size().x, (1 << 29) + 1);
  EXPECT_EQ(in.world.solid_count(), 2);
}

// Class 3: 2^12 one-voxel instances in distinct chunks touch 2^12 chunks (128 MiB at edge 32):
// refused under a 64 MiB limit before the chunks are allocated, read under a larger one.
// The same below z = -2^28, where packed chunk keys used to collide and count one chunk.
class HostileVoxSwarm : public ::testing::TestWithParam<int> {};
INSTANTIATE_TEST_SUITE_P(RootOffsets, HostileVoxSwarm,
                         ::testing::Values(0, -(1 << 28), (1 << 28) + 12345));

TEST_P(HostileVoxSwarm, ManyInstancesInDistinctChunksAreCountedBeforePlacing) {
  std::vector<Bytes> parts{
      size_chunk(1, 1, 1), xyzi_chunk({{0, 0, 0, 1}}),
      transform_chunk(0, 1, -1, {{"_t", "0 0 " + std::to_string(GetParam())}})};
  std::vector<int> children;
  const int n = 4096;
  for (int i = 0; i < n; ++i) children.push_back(2 + 2 * i);
  parts.push_back(group_chunk(1, children));
  for (int i = 0; i < n; ++i) {
    parts.push_back(transform_chunk(
        2 + 2 * i, 3 + 2 * i, 0,
        {{"_t", std::to_string(64 * (i % 64)) + " " + std::to_string(64 * (i / 64)) + " 0"}}));
    parts.push_back(shape_chunk(3 + 2 * i, 0));
  }
  const Bytes file = vox_file(parts);
  VoxImportOptions tight;
  tight.memory_limit_bytes = 64 * kMiB;
  const std::string msg = error_of([&] { parse_vox(file, "swarm.vox", tight); });
  EXPECT_NE(msg.find("swarm.vox"), std::string::npos) << msg;
  EXPECT_NE(msg.find("memory limit of 64.0 MiB"), std::string::npos) << msg;
  EXPECT_NE(msg.find("chunks of 32^3"), std::string::npos) << msg;
  VoxImportOptions roomy;
  roomy.memory_limit_bytes = 512 * kMiB;
  EXPECT_EQ(parse_vox(file, "swarm.vox", roomy).world.solid_count(), n);
}

// A 1 KB TDCZ model that inflates to 64 MiB is refused under a 32 MiB limit before inflating.
TEST(HostileVox, CompressedModelsAreCountedBeforeInflating) {
  const int e = 400;  // 400^3 = 64e6 voxels of zeros
  Bytes zeros(static_cast<std::size_t>(e) * e * e, 0);
  uLongf packed_size = compressBound(static_cast<uLong>(zeros.size()));
  Bytes packed(packed_size);
  ASSERT_EQ(
      compress2(packed.data(), &packed_size, zeros.data(), static_cast<uLong>(zeros.size()), 9),
      Z_OK);
  packed.resize(packed_size);
  Bytes c;
  for (int k = 0; k < 3; ++k) put32(c, e);
  c.insert(c.end(), packed.begin(), packed.end());
  const Bytes file = vox_file({size_chunk(e, e, e), chunk("TDCZ", c)});
  VoxImportOptions tight;
  tight.memory_limit_bytes = 32 * kMiB;
  EXPECT_THROW(parse_vox(file, "td.vox", tight), ResourceLimitError);
  VoxImportOptions roomy;
  roomy.memory_limit_bytes = 512 * kMiB;
  EXPECT_EQ(parse_vox(file, "td.vox", roomy).world.solid_count(), 0);
}

TEST(HostileVox, DeliberateLeniencies) {
  const Bytes model_chunks[] = {size_chunk(2, 2, 2), xyzi_chunk({{1, 1, 1, 5}})};
  auto with_rotation = [&](const std::string& r) {
    return vox_file({model_chunks[0], model_chunks[1], transform_chunk(0, 1, -1, {{"_r", r}}),
                     shape_chunk(1, 0)});
  };
  EXPECT_NO_THROW(parse_vox(with_rotation("4"), "r.vox"));
  EXPECT_NE(error_of([&] { parse_vox(with_rotation("4x"), "r.vox"); }).find("bad rotation"),
            std::string::npos);
  // Bytes after MAIN are refused; old versions are refused; newer ones are read.
  Bytes trailing = vox_file({model_chunks[0], model_chunks[1]});
  trailing.push_back(0);
  EXPECT_NE(error_of([&] { parse_vox(trailing, "t.vox"); }).find("1 bytes after the MAIN chunk"),
            std::string::npos);
  EXPECT_THROW(parse_vox(vox_file({model_chunks[0], model_chunks[1]}, 100), "old.vox"),
               FormatError);
  EXPECT_EQ(
      parse_vox(vox_file({model_chunks[0], model_chunks[1]}, 201), "new.vox").world.solid_count(),
      1);
}

namespace {

// The world section's grid starts after the section header (12 bytes) and the palette (1024).
constexpr std::size_t kGridAt = 20 + 12 + 1024;

void put_i32(Bytes& b, std::size_t at, std::int32_t v) {
  std::memcpy(b.data() + at, &v, 4);
}

}  // namespace

TEST(HostileWorldFile, CoordinatesBoundsAndDuplicatesAreChecked) {
  // Bounded world, one uniform chunk: grid = edge, value size, background, flag, 6 x bound, count,
  // then the chunk: 3 x coordinate, kind, value.
  World w(8, Box3i::from_size({16, 16, 16}));
  w.voxels.fill(Box3i::from_size({8, 8, 8}), 3);
  const Bytes good = encode_world_file(w);
  ASSERT_EQ(parse_world_file(good, "ok.vfw").world.solid_count(), 512);
  const std::size_t bounds_at = kGridAt + 10, chunk_at = bounds_at + 24 + 8;

  Bytes b = good;  // bounds of +-2^31 (the probe's render crash)
  put_i32(b, bounds_at, INT32_MIN);
  put_i32(b, bounds_at + 12, INT32_MAX);
  test::fix_world_file_checksums(b);
  EXPECT_NE(error_of([&] {
              parse_world_file(b, "b.vfw");
            }).find("outside the supported coordinate range"),
            std::string::npos);

  // Unbounded copies: a uniform chunk at (-2^31, 0, 0) must not appear at the origin.
  World u(8);
  u.voxels.fill(Box3i::from_size({8, 8, 8}), 3);
  u.voxels.fill({{64, 0, 0}, {72, 8, 8}}, 4);
  const Bytes ugood = encode_world_file(u);
  const std::size_t uchunk_at = kGridAt + 10 + 8;
  b = ugood;
  put_i32(b, uchunk_at, INT32_MIN);
  test::fix_world_file_checksums(b);
  EXPECT_NE(error_of([&] {
              parse_world_file(b, "far.vfw");
            }).find("outside the supported coordinate range"),
            std::string::npos);
  b = ugood;  // a chunk coordinate whose voxels overflow 32 bits (2^28 chunks of 8)
  put_i32(b, uchunk_at, 1 << 28);
  test::fix_world_file_checksums(b);
  EXPECT_THROW(parse_world_file(b, "near.vfw"), FormatError);
  b = ugood;  // the second chunk given the first one's coordinate
  put_i32(b, uchunk_at + 12 + 1 + 1, 0);
  test::fix_world_file_checksums(b);
  EXPECT_NE(error_of([&] { parse_world_file(b, "dup.vfw"); }).find("appears twice"),
            std::string::npos);
  (void)chunk_at;
}

TEST(HostileWorldFile, DecodedSizeIsCountedBeforeDecompressing) {
  // 64 dense chunks of edge 64 (16 MiB decoded) from under 128 KiB: refused under 8 MiB.
  World w(64);
  for (int i = 0; i < 64; ++i) w.voxels.set({64 * i, 0, 0}, 1);
  const Bytes file = encode_world_file(w);
  EXPECT_LT(file.size(), 128u * 1024);
  WorldFileReadOptions tight;
  tight.memory_limit_bytes = 8 * kMiB;
  const std::string msg = error_of([&] { parse_world_file(file, "dense.vfw", tight); });
  EXPECT_NE(msg.find("dense.vfw"), std::string::npos) << msg;
  EXPECT_NE(msg.find("64 dense"), std::string::npos) << msg;
  EXPECT_EQ(parse_world_file(file, "dense.vfw").world.solid_count(), 64);
}

TEST(HostileWorldFile, UniformChunksCutByTheBoundsAreCountedAsDense) {
  // Bounds one voxel thick through 64 chunks of edge 128, each chunk a 14-byte uniform record:
  // every one becomes a dense 2 MiB chunk (the part outside the bounds reads the background).
  Bytes grid;
  auto put = [&](const void* p, std::size_t n) {
    grid.insert(grid.end(), (const std::uint8_t*)p, (const std::uint8_t*)p + n);
  };
  const std::uint32_t edge = 128, vsize = 1;
  const std::uint8_t background = 0, flag = 1, uniform = 0, value = 5;
  const std::int32_t bounds[6] = {0, 0, 0, 1, 1024, 1024};
  const std::uint64_t count = 64;
  put(&edge, 4), put(&vsize, 4), put(&background, 1), put(&flag, 1), put(bounds, 24),
      put(&count, 8);
  for (std::int32_t y = 0; y < 8; ++y)
    for (std::int32_t z = 0; z < 8; ++z) {
      const std::int32_t c[3] = {0, y, z};
      put(c, 12), put(&uniform, 1), put(&value, 1);
    }
  Bytes file{'V', 'X', 'F', 'W', 'O', 'R', 'L', 'D'};
  const std::uint32_t header[3] = {1, 1, 0};
  file.insert(file.end(), (const std::uint8_t*)header, (const std::uint8_t*)header + 12);
  const std::uint32_t kind = 1;
  const std::uint64_t size = 1024 + grid.size();
  file.insert(file.end(), (const std::uint8_t*)&kind, (const std::uint8_t*)&kind + 4);
  file.insert(file.end(), (const std::uint8_t*)&size, (const std::uint8_t*)&size + 8);
  file.insert(file.end(), 1024, 0);  // palette
  file.insert(file.end(), grid.begin(), grid.end());
  file.insert(file.end(), 4, 0);  // checksum, fixed below
  test::fix_world_file_checksums(file);
  WorldFileReadOptions tight;
  tight.memory_limit_bytes = 32 * kMiB;
  const std::string msg = error_of([&] { parse_world_file(file, "cut.vfw", tight); });
  EXPECT_NE(msg.find("64 dense"), std::string::npos) << msg;
  EXPECT_EQ(parse_world_file(file, "cut.vfw").world.solid_count(), 1024 * 1024);
}

TEST(HostileWorldFile, FieldOptionsAreValidated) {
  World w(8, Box3i::from_size({8, 8, 8}));
  w.voxels.set({1, 1, 1}, 1);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.max_distance = 4;
  const DistanceField f = compute_distance_field(w, o);
  const Bytes good = encode_world_file(w, {&f});
  ASSERT_EQ(parse_world_file(good, "f.vfw").fields.size(), 1u);
  // The field section follows the world section.
  std::uint64_t world_size;
  std::memcpy(&world_size, good.data() + 24, 8);
  const std::size_t field_at = 20 + 12 + static_cast<std::size_t>(world_size) + 4 + 12;
  auto patched = [&](std::size_t offset, double v) {
    Bytes b = good;
    std::memcpy(b.data() + field_at + offset, &v, 8);
    test::fix_world_file_checksums(b);
    return error_of([&] { parse_world_file(b, "f.vfw"); });
  };
  EXPECT_NE(patched(4, std::nan("")).find("invalid clamp"), std::string::npos);
  EXPECT_NE(patched(12, -1.0).find("invalid voxel spacing"), std::string::npos);
  Bytes inv = good;  // domain begin.x = 9 > end.x = 8
  put_i32(inv, field_at + 44, 9);
  test::fix_world_file_checksums(inv);
  EXPECT_NE(error_of([&] { parse_world_file(inv, "f.vfw"); }).find("inverted field domain"),
            std::string::npos);
}
