// .npy against bytes written by NumPy itself (numpy 1.24, np.save) and hand-made headers.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include <unistd.h>

#include "voxfield/npy.h"

using namespace voxfield;

namespace {

std::vector<std::uint8_t> npy_bytes(const std::string& header_dict,
                                    const std::vector<std::uint8_t>& data, int major = 1) {
  std::string h = header_dict;
  const std::size_t prefix = major == 1 ? 10 : 12;
  while ((prefix + h.size() + 1) % 64) h.push_back(' ');
  h.push_back('\n');
  std::vector<std::uint8_t> b{0x93, 'N', 'U', 'M', 'P', 'Y', static_cast<std::uint8_t>(major), 0};
  const std::uint32_t n = static_cast<std::uint32_t>(h.size());
  b.push_back(n & 0xFF);
  b.push_back((n >> 8) & 0xFF);
  if (major != 1) {
    b.push_back((n >> 16) & 0xFF);
    b.push_back(n >> 24);
  }
  b.insert(b.end(), h.begin(), h.end());
  b.insert(b.end(), data.begin(), data.end());
  return b;
}

// a = zeros((3, 2, 2), uint8); a[1,0,0] = 5; a[2,1,1] = 7; a[0,1,0] = 9
// np.save of np.asfortranarray(a) and of a (C order), as NumPy 1.24 wrote them.
const std::string kFortranHeader = "{'descr': '|u1', 'fortran_order': True, 'shape': (3, 2, 2), }";
const std::vector<std::uint8_t> kFortranData{0x00, 0x05, 0x00, 0x09, 0x00, 0x00,
                                             0x00, 0x00, 0x00, 0x00, 0x00, 0x07};
const std::string kCHeader = "{'descr': '|u1', 'fortran_order': False, 'shape': (3, 2, 2), }";
const std::vector<std::uint8_t> kCData{0x00, 0x00, 0x09, 0x00, 0x05, 0x00,
                                       0x00, 0x00, 0x00, 0x00, 0x00, 0x07};

void expect_reference_volume(const NpyVolume& v) {
  EXPECT_EQ(v.dtype, DType::kUInt8);
  EXPECT_EQ(v.dims, (Vec3i{3, 2, 2}));
  auto at = [&](int x, int y, int z) { return v.value(x + 3 * (y + 2 * z)); };
  EXPECT_EQ(at(1, 0, 0), 5);
  EXPECT_EQ(at(2, 1, 1), 7);
  EXPECT_EQ(at(0, 1, 0), 9);
  double sum = 0;
  for (int i = 0; i < 12; ++i) sum += v.value(i);
  EXPECT_EQ(sum, 21);
}

}  // namespace

TEST(Npy, ReadsNumpyFortranAndCOrder) {
  const auto f = npy_bytes(kFortranHeader, kFortranData);
  ASSERT_EQ(f.size(), 140u);  // NumPy's file size for this array
  expect_reference_volume(parse_npy(f, "f.npy"));
  expect_reference_volume(parse_npy(npy_bytes(kCHeader, kCData), "c.npy"));
}

TEST(Npy, WritesExactlyWhatNumpyWrites) {
  NpyVolume v{DType::kUInt8, {3, 2, 2}, kFortranData};
  EXPECT_EQ(encode_npy(v), npy_bytes(kFortranHeader, kFortranData));
}

TEST(Npy, BigEndianAndVersion2) {
  // np.arange(12, dtype='>i2').reshape(3, 2, 2) in C order: a[x, y, z] = 4x + 2y + z.
  std::vector<std::uint8_t> data;
  for (int i = 0; i < 12; ++i) data.insert(data.end(), {0, static_cast<std::uint8_t>(i)});
  for (int major : {1, 2, 3}) {
    const NpyVolume v = parse_npy(
        npy_bytes("{'descr': '>i2', 'fortran_order': False, 'shape': (3, 2, 2), }", data, major),
        "be.npy");
    EXPECT_EQ(v.dtype, DType::kInt16);
    for (int z = 0; z < 2; ++z)
      for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 3; ++x) EXPECT_EQ(v.value(x + 3 * (y + 2 * z)), 4 * x + 2 * y + z);
  }
}

TEST(Npy, EveryDtypeRoundTrips) {
  const DType all[] = {DType::kBool,   DType::kInt8,    DType::kUInt8,
                       DType::kInt16,  DType::kUInt16,  DType::kInt32,
                       DType::kUInt32, DType::kFloat32, DType::kFloat64};
  for (DType t : all) {
    NpyVolume v{t, {5, 3, 2}, std::vector<std::uint8_t>(30 * dtype_size(t))};
    for (std::size_t i = 0; i < v.bytes.size(); ++i)
      v.bytes[i] = static_cast<std::uint8_t>(i * 7 % 3);
    if (t == DType::kBool)
      for (auto& b : v.bytes) b = b ? 1 : 0;
    const NpyVolume back = parse_npy(encode_npy(v), "rt.npy");
    EXPECT_EQ(back.dtype, t) << dtype_name(t);
    EXPECT_EQ(back.dims, v.dims);
    EXPECT_EQ(back.bytes, v.bytes) << dtype_name(t);
  }
}

TEST(Npy, FloatSamplesAreEachValueAsAFloat) {
  // Every dtype, bytes that make negative, large and fractional values: the meshers' float
  // samples are value(i) rounded to float, sample by sample (a bool byte other than 0 is true).
  const DType all[] = {DType::kBool,   DType::kInt8,    DType::kUInt8,  DType::kInt16,
                       DType::kUInt16, DType::kInt32,   DType::kUInt32, DType::kInt64,
                       DType::kUInt64, DType::kFloat32, DType::kFloat64};
  std::mt19937 rng(7);
  for (DType t : all) {
    NpyVolume v{t, {5, 3, 2}, std::vector<std::uint8_t>(30 * dtype_size(t))};
    for (auto& b : v.bytes) b = static_cast<std::uint8_t>(rng());
    if (t == DType::kFloat32 || t == DType::kFloat64)  // finite values (random bytes may not be)
      for (std::int64_t i = 0; i < 30; ++i) {
        const double x = (static_cast<double>(rng()) - 2147483648.0) / 1024.0;
        if (t == DType::kFloat32) {
          const float f = static_cast<float>(x);
          std::memcpy(v.bytes.data() + 4 * i, &f, 4);
        } else {
          std::memcpy(v.bytes.data() + 8 * i, &x, 8);
        }
      }
    const std::vector<float> samples = float_samples(v, "s.npy");
    ASSERT_EQ(samples.size(), 30u) << dtype_name(t);
    for (std::int64_t i = 0; i < 30; ++i)
      EXPECT_EQ(samples[static_cast<std::size_t>(i)], static_cast<float>(v.value(i)))
          << dtype_name(t) << " sample " << i;
  }
  // A float64 past float32's range is refused, naming the file and the sample's byte.
  NpyVolume big{DType::kFloat64, {3, 2, 1}, std::vector<std::uint8_t>(6 * 8)};
  big.file_data_offset = 128;
  const double huge = 1e300;
  std::memcpy(big.bytes.data() + 8 * 4, &huge, 8);  // sample (1, 1, 0)
  try {
    float_samples(big, "big.npy");
    FAIL() << "a float64 of 1e300 became a float32 sample";
  } catch (const FormatError& e) {
    EXPECT_EQ(e.offset(), 128u + 8 * 4) << e.what();
    EXPECT_NE(std::string(e.what()).find("big.npy"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not fit a float32 sample"), std::string::npos);
  }
}

TEST(Npy, RejectsOtherShapesDtypesAndTruncation) {
  const std::vector<std::uint8_t> d(12);
  EXPECT_THROW(
      parse_npy(npy_bytes("{'descr': '|u1', 'fortran_order': False, 'shape': (12,), }", d), "a"),
      FormatError);
  EXPECT_THROW(
      parse_npy(npy_bytes("{'descr': '|u1', 'fortran_order': False, 'shape': (3, 2, 2, 1), }", d),
                "a"),
      FormatError);
  EXPECT_THROW(parse_npy(npy_bytes("{'descr': '<c8', 'fortran_order': False, 'shape': (3, 1, 1), }",
                                   std::vector<std::uint8_t>(24)),
                         "a"),
               FormatError);
  EXPECT_THROW(
      parse_npy(npy_bytes("{'descr': '|O', 'fortran_order': False, 'shape': (3, 2, 2), }", d), "a"),
      FormatError);
  // 64-bit integers (NumPy's default) are read, on purpose (docs/limits.md); 16-byte floats are
  // not.
  EXPECT_EQ(parse_npy(npy_bytes("{'descr': '<i8', 'fortran_order': False, 'shape': (3, 1, 1), }",
                                std::vector<std::uint8_t>(24)),
                      "a")
                .dtype,
            DType::kInt64);
  EXPECT_THROW(
      parse_npy(npy_bytes("{'descr': '<f16', 'fortran_order': False, 'shape': (3, 1, 1), }",
                          std::vector<std::uint8_t>(48)),
                "a"),
      FormatError);
  EXPECT_THROW(
      parse_npy(npy_bytes("{'descr': '|u1', 'fortran_order': False, 'shape': (0, 2, 2), }", {}),
                "a"),
      FormatError);
  EXPECT_THROW(
      parse_npy(
          npy_bytes("{'descr': '|u1', 'fortran_order': False, 'shape': (99999, 99999, 99999), }",
                    d),
          "a"),
      FormatError);
  EXPECT_THROW(parse_npy(npy_bytes("{'descr': '|u1', 'shape': (3, 2, 2), }", d), "a"), FormatError);
  const auto good = npy_bytes(kFortranHeader, kFortranData);
  for (std::size_t n = 0; n < good.size(); ++n) {
    EXPECT_THROW(parse_npy(std::span(good.data(), n), "cut.npy"), FormatError) << n;
  }
  try {
    parse_npy(npy_bytes(kFortranHeader, {1, 2, 3}), "short.npy");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("short.npy"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("12 bytes"), std::string::npos) << e.what();
  }
}

TEST(Npy, WorldConversion) {
  const NpyVolume v = parse_npy(npy_bytes(kFortranHeader, kFortranData), "w.npy");
  const World w = world_from_npy(v, "w.npy", 8);
  EXPECT_EQ(w.solid_count(), 3);
  EXPECT_EQ(w.voxels.get({1, 0, 0}), 5);
  EXPECT_EQ(w.voxels.get({2, 1, 1}), 7);
  const NpyVolume back = npy_from_world(w, Box3i::from_size({3, 2, 2}));
  EXPECT_EQ(back.bytes, kFortranData);
  // Values that are not materials are refused with their position.
  NpyVolume f{DType::kFloat32, {2, 1, 1}, std::vector<std::uint8_t>(8)};
  const float vals[2] = {0.0f, 2.5f};
  std::memcpy(f.bytes.data(), vals, 8);
  try {
    world_from_npy(f, "frac.npy");
    FAIL();
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("a[1, 0, 0]"), std::string::npos) << e.what();
  }
  NpyVolume big{DType::kInt32, {1, 1, 1}, {0x00, 0x01, 0x00, 0x00}};  // 256
  EXPECT_THROW(world_from_npy(big, "big.npy"), FormatError);
}

namespace {

// A temporary file holding `bytes`, removed at the end of the test.
struct TempFile {
  std::filesystem::path path;
  TempFile(const std::string& name, const std::vector<std::uint8_t>& bytes)
      : path(std::filesystem::temp_directory_path() /
             ("voxfield_npy_part_" + std::to_string(::getpid()) + "_" + name)) {
    std::ofstream(path, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }
  ~TempFile() { std::filesystem::remove(path); }
};

}  // namespace

// Parts of arrays (what voxfield-mpi's ranks read) against the whole array read at once: every
// slice range of Fortran- and C-order files, little- and big-endian, several dtypes.
TEST(Npy, PartsEqualTheWholeArraysSlices) {
  std::mt19937 rng(11);
  struct Kind {
    const char* descr;
    int size;
  };
  for (const Kind k :
       {Kind{"|u1", 1}, Kind{"<i2", 2}, Kind{">f4", 4}, Kind{"<f8", 8}, Kind{"|b1", 1}}) {
    for (bool fortran : {true, false}) {
      const Vec3i d{2 + static_cast<int>(rng() % 6), 1 + static_cast<int>(rng() % 5),
                    3 + static_cast<int>(rng() % 7)};
      std::vector<std::uint8_t> data(static_cast<std::size_t>(d.x * d.y * d.z * k.size));
      for (auto& b : data) b = static_cast<std::uint8_t>(rng() % 3 == 0 ? rng() : 0);
      const std::string header = std::string("{'descr': '") + k.descr +
                                 "', 'fortran_order': " + (fortran ? "True" : "False") +
                                 ", 'shape': (" + std::to_string(d.x) + ", " + std::to_string(d.y) +
                                 ", " + std::to_string(d.z) + "), }";
      const auto bytes = npy_bytes(header, data, fortran ? 1 : 2);
      const TempFile file(std::string(k.descr + 1) + (fortran ? "f" : "c") + ".npy", bytes);
      const NpyVolume whole = parse_npy(bytes, "whole");
      const NpyVolume head = read_npy_header(file.path);
      EXPECT_EQ(head.dims, d);
      EXPECT_EQ(head.dtype, whole.dtype);
      EXPECT_TRUE(head.bytes.empty());
      const std::size_t slice = static_cast<std::size_t>(d.x * d.y * k.size);
      for (int z0 = 0; z0 < d.z; ++z0)
        for (int z1 = z0 + 1; z1 <= d.z; ++z1) {
          const NpyVolume part = read_npy_part(file.path, z0, z1);
          const std::string what = std::string(k.descr) + (fortran ? " F" : " C") + " z " +
                                   std::to_string(z0) + ".." + std::to_string(z1);
          ASSERT_EQ(part.dims, (Vec3i{d.x, d.y, z1 - z0})) << what;
          EXPECT_EQ(part.file_origin, (Vec3i{0, 0, z0})) << what;
          const std::vector<std::uint8_t> expect(
              whole.bytes.begin() + static_cast<std::ptrdiff_t>(z0 * slice),
              whole.bytes.begin() + static_cast<std::ptrdiff_t>(z1 * slice));
          EXPECT_EQ(part.bytes, expect) << what;
          // Every value's file offset is where the whole array has it.
          for (std::int64_t i = 0; i < part.count(); i += 3) {
            EXPECT_EQ(part.file_offset_of(i),
                      whole.file_offset_of(i + static_cast<std::int64_t>(z0) * d.x * d.y))
                << what;
          }
        }
    }
  }
}

TEST(Npy, PartsRefuseBadSlicesAndShortFiles) {
  const TempFile good("good.npy", npy_bytes(kFortranHeader, kFortranData));
  EXPECT_THROW(read_npy_part(good.path, 1, 1), InvalidArgument);
  EXPECT_THROW(read_npy_part(good.path, -1, 1), InvalidArgument);
  EXPECT_THROW(read_npy_part(good.path, 0, 3), InvalidArgument);
  auto cut = npy_bytes(kFortranHeader, kFortranData);
  cut.pop_back();
  const TempFile short_file("short.npy", cut);
  EXPECT_THROW(read_npy_header(short_file.path), FormatError);
  EXPECT_THROW(read_npy_part(short_file.path, 0, 1), FormatError);
  const TempFile not_npy("not.npy", {'h', 'e', 'l', 'l', 'o'});
  EXPECT_THROW(read_npy_header(not_npy.path), FormatError);
  EXPECT_THROW(read_npy_header(std::filesystem::path("/nonexistent/voxfield.npy")), IoError);
  // A value that is no material names its index in the whole array and its offset in the file.
  const std::string f32 = "{'descr': '<f4', 'fortran_order': True, 'shape': (3, 2, 2), }";
  std::vector<std::uint8_t> floats(12 * 4, 0);
  const float half = 0.5f;
  std::memcpy(floats.data() + 4 * (2 + 3 * (1 + 2 * 1)), &half, 4);  // a[2, 1, 1]
  const auto frac_bytes = npy_bytes(f32, floats);
  const TempFile frac("frac.npy", frac_bytes);
  try {
    (void)world_from_npy(read_npy_part(frac.path, 1, 2), frac.path.string());
    FAIL() << "a fraction was read as a material";
  } catch (const FormatError& e) {
    EXPECT_NE(std::string(e.what()).find("a[2, 1, 1] holds 0.5"), std::string::npos) << e.what();
    EXPECT_EQ(e.offset(), frac_bytes.size() - floats.size() + 4 * 11) << e.what();
  }
  // The part's world sits at the part's place.
  const World w = world_from_npy(read_npy_part(good.path, 1, 2), "good");
  EXPECT_EQ(w.voxels.get({2, 1, 1}), 7);
  EXPECT_EQ(w.voxels.get({1, 0, 0}), 0);  // slice 0 is not part of it
  EXPECT_EQ(w.solid_count(), 1);
}
