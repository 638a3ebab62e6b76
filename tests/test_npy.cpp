// .npy against bytes written by NumPy itself (numpy 1.24, np.save) and hand-made headers.
#include <gtest/gtest.h>

#include <string>

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
