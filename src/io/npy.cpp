// voxfield — NumPy .npy reader and writer.
//
// Format: NumPy's "NEP 1 — A simple file format for NumPy arrays": magic "\x93NUMPY", major and
// minor version, a little-endian header length (2 bytes in 1.0, 4 bytes in 2.0/3.0), then a Python
// dict literal with 'descr', 'fortran_order' and 'shape', padded with spaces to a multiple of 64
// bytes and ended by a newline. The parser accepts exactly that literal grammar, no more.
#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>

#include "byte_reader.h"
#include "npy_sample_types.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/npy.h"

namespace voxfield {
namespace {

struct DTypeInfo {
  DType type;
  char kind;  // NumPy kind letter
  int size;
  const char* name;
};
constexpr DTypeInfo kDTypes[] = {
    {DType::kBool, 'b', 1, "bool"},       {DType::kInt8, 'i', 1, "int8"},
    {DType::kUInt8, 'u', 1, "uint8"},     {DType::kInt16, 'i', 2, "int16"},
    {DType::kUInt16, 'u', 2, "uint16"},   {DType::kInt32, 'i', 4, "int32"},
    {DType::kUInt32, 'u', 4, "uint32"},   {DType::kInt64, 'i', 8, "int64"},
    {DType::kUInt64, 'u', 8, "uint64"},   {DType::kFloat32, 'f', 4, "float32"},
    {DType::kFloat64, 'f', 8, "float64"},
};

const DTypeInfo& info(DType t) {
  for (const auto& d : kDTypes)
    if (d.type == t) return d;
  throw InvalidArgument("unknown dtype");
}

// Minimal parser for the header's Python dict literal.
class HeaderParser {
 public:
  HeaderParser(const std::string& text, const std::string& name, std::uint64_t base)
      : s_(text), name_(name), base_(base) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw FormatError(name_, base_ + pos_, "bad .npy header: " + what);
  }
  void ws() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool eat(char c) {
    ws();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!eat(c)) fail(std::string("expected '") + c + "'");
  }
  std::string quoted() {
    ws();
    if (pos_ >= s_.size() || (s_[pos_] != '\'' && s_[pos_] != '"')) fail("expected a string");
    const char q = s_[pos_++];
    const std::size_t start = pos_;
    while (pos_ < s_.size() && s_[pos_] != q) ++pos_;
    if (pos_ >= s_.size()) fail("unterminated string");
    return s_.substr(start, pos_++ - start);
  }
  bool boolean() {
    ws();
    if (s_.compare(pos_, 4, "True") == 0) {
      pos_ += 4;
      return true;
    }
    if (s_.compare(pos_, 5, "False") == 0) {
      pos_ += 5;
      return false;
    }
    fail("expected True or False");
  }
  std::vector<std::int64_t> tuple() {
    expect('(');
    std::vector<std::int64_t> out;
    while (!eat(')')) {
      ws();
      std::int64_t v = 0;
      bool any = false;
      while (pos_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[pos_]))) {
        if (v > (std::int64_t{1} << 40)) fail("dimension too large");
        v = v * 10 + (s_[pos_++] - '0');
        any = true;
      }
      ws();
      if (pos_ < s_.size() && s_[pos_] == 'L') ++pos_;  // Python 2 long suffix
      if (!any) fail("expected a dimension");
      out.push_back(v);
      if (out.size() > 32) fail("too many dimensions");
      if (!eat(',')) {
        expect(')');
        break;
      }
    }
    return out;
  }

  std::string descr;
  bool fortran = false;
  std::vector<std::int64_t> shape;

  void parse() {
    bool have_descr = false, have_order = false, have_shape = false;
    expect('{');
    while (!eat('}')) {
      const std::string key = quoted();
      expect(':');
      for (const std::string& seen : keys_) {
        if (seen == key) fail("key '" + key + "' given twice");
      }
      keys_.push_back(key);
      if (key == "descr") {
        descr = quoted();
        have_descr = true;
      } else if (key == "fortran_order") {
        fortran = boolean();
        have_order = true;
      } else if (key == "shape") {
        shape = tuple();
        have_shape = true;
      } else {
        fail("unexpected key '" + key + "'");
      }
      if (!eat(',')) {
        expect('}');
        break;
      }
    }
    if (!have_descr || !have_order || !have_shape)
      fail("needs 'descr', 'fortran_order' and 'shape'");
  }

 private:
  const std::string& s_;
  const std::string& name_;
  std::uint64_t base_;
  std::size_t pos_ = 0;
  std::vector<std::string> keys_;
};

// A value as users wrote it: integers without a fraction, others with enough digits.
std::string number_text(double m) {
  char buf[40];
  if (std::isfinite(m) && std::floor(m) == m && std::abs(m) < 1e15) {
    std::snprintf(buf, sizeof buf, "%.0f", m);
  } else {
    std::snprintf(buf, sizeof buf, "%.9g", m);
  }
  return buf;
}

}  // namespace

std::size_t dtype_size(DType t) {
  return static_cast<std::size_t>(info(t).size);
}
const char* dtype_name(DType t) {
  return info(t).name;
}

double NpyVolume::value(std::int64_t i) const {
  const std::uint8_t* p = bytes.data() + static_cast<std::size_t>(i) * dtype_size(dtype);
  return detail::npy::with_sample_type(
      dtype, [&]<class T>() { return detail::npy::sample_as_double<T>(p); });
}

Vec3i NpyVolume::file_index_of(std::int64_t i) const {
  const std::int64_t X = dims.x, Y = dims.y;
  return file_origin + Vec3i{static_cast<std::int32_t>(i % X),
                             static_cast<std::int32_t>((i / X) % Y),
                             static_cast<std::int32_t>(i / (X * Y))};
}

std::uint64_t NpyVolume::file_offset_of(std::int64_t i) const {
  const Vec3i whole = file_dims.x > 0 ? file_dims : dims;
  const std::int64_t X = whole.x, Y = whole.y, Z = whole.z;
  const Vec3i p = file_index_of(i);
  const std::int64_t in_file = file_c_order ? (p.x * Y + p.y) * Z + p.z : (p.z * Y + p.y) * X + p.x;
  return file_data_offset + static_cast<std::uint64_t>(in_file) * dtype_size(dtype);
}

namespace {

// A .npy header, validated against the bytes that follow it (`available`): everything the readers
// need before the data.
struct Header {
  const DTypeInfo* type = nullptr;
  bool swap = false;     // big-endian data of a multi-byte type
  bool c_order = false;  // z fastest
  int rank = 3;
  Vec3i dims;
  std::uint64_t data_offset = 0, data_bytes = 0, count = 0;
};

Header read_header(detail::ByteReader& r, const std::function<std::uint64_t()>& available,
                   const NpyReadOptions& options) {
  static constexpr std::uint8_t kMagic[6] = {0x93, 'N', 'U', 'M', 'P', 'Y'};
  auto magic = r.take(6, "magic");
  if (!std::equal(magic.begin(), magic.end(), kMagic)) r.fail_at(0, "not a .npy file (bad magic)");
  const int major = r.u8("version"), minor = r.u8("version");
  std::uint32_t header_len;
  if (major == 1) {
    header_len = r.u16("header length");
  } else if (major == 2 || major == 3) {
    header_len = r.u32("header length");
  } else {
    r.fail_at(6, "unsupported .npy version " + std::to_string(major) + "." + std::to_string(minor));
  }
  const std::uint64_t header_at = r.offset();
  auto header_bytes = r.take(header_len, "header");
  const std::string header(header_bytes.begin(), header_bytes.end());
  const std::string& name = r.name();
  HeaderParser h(header, name, header_at);
  h.parse();

  // descr: byte order character then kind and size, e.g. "<f4", "|u1", "|b1".
  if (h.descr.size() < 3) r.fail_at(header_at, "unsupported dtype '" + h.descr + "'");
  const char order = h.descr[0];
  const char kind = h.descr[1];
  int size = 0;
  for (std::size_t i = 2; i < h.descr.size(); ++i) {
    if (!std::isdigit(static_cast<unsigned char>(h.descr[i])) || size > 64) {
      r.fail_at(header_at, "unsupported dtype '" + h.descr + "'");
    }
    size = size * 10 + (h.descr[i] - '0');
  }
  const DTypeInfo* found = nullptr;
  for (const auto& d : kDTypes)
    if (d.kind == kind && d.size == size) found = &d;
  if (!found || (order != '<' && order != '>' && order != '|' && order != '=')) {
    r.fail_at(header_at,
              "unsupported dtype '" + h.descr +
                  "' (voxfield reads bool, int8/16/32/64, uint8/16/32/64, float32, float64)");
  }
  if (options.rank < 1 || options.rank > 3) throw InvalidArgument("parse_npy: rank must be 1..3");
  if (h.shape.size() != static_cast<std::size_t>(options.rank)) {
    r.fail_at(header_at, (options.rank == 3
                              ? std::string("expected a 3-D array a[x, y, z], got ")
                              : "expected a " + std::to_string(options.rank) + "-D array, got ") +
                             std::to_string(h.shape.size()) + " dimensions");
  }
  h.shape.resize(3, 1);
  Header out;
  out.rank = options.rank;
  out.type = found;
  for (int k = 0; k < 3; ++k) {
    if (h.shape[k] < 1 || h.shape[k] > kCoordLimit) {
      r.fail_at(header_at, "dimension " + std::to_string(k) + " is " + std::to_string(h.shape[k]) +
                               ", outside 1..2^29 (the supported coordinate range)");
    }
    out.dims[k] = static_cast<std::int32_t>(h.shape[k]);
  }
  // Each dimension is below 2^30, but their product may not fit in 64 bits: saturate, then compare.
  out.count = mul_sat(
      mul_sat(static_cast<std::uint64_t>(h.shape[0]), static_cast<std::uint64_t>(h.shape[1])),
      static_cast<std::uint64_t>(h.shape[2]));
  out.data_bytes = mul_sat(out.count, static_cast<std::uint64_t>(size));
  const std::uint64_t follow = available();
  if (out.data_bytes > follow) {
    r.fail("the shape (" + std::to_string(h.shape[0]) + ", " + std::to_string(h.shape[1]) + ", " +
           std::to_string(h.shape[2]) + ") of " + found->name + " needs " +
           (out.data_bytes == UINT64_MAX ? std::string("more than 2^64")
                                         : std::to_string(out.data_bytes)) +
           " bytes of data but only " + std::to_string(follow) + " bytes follow the header");
  }
  if (out.data_bytes < follow) {
    r.fail_at(r.offset() + out.data_bytes,
              std::to_string(follow - out.data_bytes) +
                  " bytes after the array data (a damaged or concatenated file?)");
  }
  out.data_offset = r.offset();
  out.c_order = !h.fortran;
  out.swap = size > 1 && order == '>';
  return out;
}

// The slices z0..z1 of the array whose file data starts at `data` (the whole array for a C-order
// file, whose slices are not contiguous; the slices alone for a Fortran-order one), into `out` x
// fastest in native byte order.
void decode_part(const Header& h, const std::uint8_t* data, std::int32_t z0, std::int32_t z1,
                 std::uint8_t* out) {
  const std::size_t size = static_cast<std::size_t>(h.type->size);
  const std::int64_t X = h.dims.x, Y = h.dims.y, Z = h.dims.z, nz = z1 - z0;
  if (!h.c_order) {
    std::memcpy(out, data, static_cast<std::size_t>(X * Y * nz) * size);
  } else {
    // C order: z fastest. Transpose to x fastest.
    for (std::int64_t x = 0; x < X; ++x)
      for (std::int64_t y = 0; y < Y; ++y)
        for (std::int64_t z = 0; z < nz; ++z) {
          const std::int64_t src = (x * Y + y) * Z + z0 + z, dst = (z * Y + y) * X + x;
          std::memcpy(out + dst * size, data + src * size, size);
        }
  }
}

void finish_values(const Header& h, std::vector<std::uint8_t>& bytes) {
  const auto size = static_cast<std::size_t>(h.type->size);
  if (h.swap) {
    for (std::size_t i = 0; i < bytes.size(); i += size) {
      std::reverse(bytes.begin() + static_cast<std::ptrdiff_t>(i),
                   bytes.begin() + static_cast<std::ptrdiff_t>(i + size));
    }
  }
  if (h.type->type == DType::kBool) {
    for (auto& b : bytes) b = b ? 1 : 0;
  }
}

NpyVolume volume_of(const Header& h) {
  NpyVolume v;
  v.rank = h.rank;
  v.dtype = h.type->type;
  v.dims = h.dims;
  v.file_dims = h.dims;
  v.file_data_offset = h.data_offset;
  v.file_c_order = h.c_order;
  return v;
}

}  // namespace

NpyVolume parse_npy(std::span<const std::uint8_t> bytes, const std::string& name,
                    const NpyReadOptions& options) {
  detail::ByteReader r(bytes, name);
  const Header h = read_header(
      r, [&] { return std::uint64_t{r.remaining()}; }, options);
  require_memory(h.data_bytes, options.memory_limit_bytes, name,
                 "the array of " + std::to_string(h.count) + " values");
  NpyVolume v = volume_of(h);
  auto data = r.take(static_cast<std::size_t>(h.data_bytes), "array data");
  v.bytes.resize(data.size());
  decode_part(h, data.data(), 0, h.dims.z, v.bytes.data());
  finish_values(h, v.bytes);
  return v;
}

NpyVolume read_npy(const std::filesystem::path& path, const NpyReadOptions& options) {
  // The file is read whole and held while its data is reordered: both count against the limit.
  const auto bytes = read_file(path, effective_memory_limit(options.memory_limit_bytes));
  NpyReadOptions rest = options;
  rest.memory_limit_bytes = remaining_memory(options.memory_limit_bytes, bytes.size());
  return parse_npy(bytes, path.string(), rest);
}

namespace {

// The header of the file behind `reader`, checked against its size.
Header header_of(const FileReader& reader, const std::string& name, const NpyReadOptions& options) {
  // The fixed prefix first (magic, version, length), then as much as the header says it takes.
  std::vector<std::uint8_t> prefix(std::min<std::uint64_t>(reader.size(), 12));
  reader.read_at(0, prefix.size(), prefix.data());
  std::uint64_t want = prefix.size();
  if (prefix.size() >= 10 && prefix[6] == 1) want = 10 + (prefix[8] | (prefix[9] << 8));
  if (prefix.size() >= 12 && (prefix[6] == 2 || prefix[6] == 3)) {
    std::uint32_t len;
    std::memcpy(&len, prefix.data() + 8, 4);
    want = 12 + std::uint64_t{len};
  }
  want = std::min(want, reader.size());
  require_memory(want, options.memory_limit_bytes, name, "the header");
  prefix.resize(static_cast<std::size_t>(want));
  reader.read_at(0, prefix.size(), prefix.data());
  detail::ByteReader r(prefix, name);
  return read_header(
      r, [&] { return reader.size() - r.offset(); }, options);
}

}  // namespace

NpyVolume read_npy_header(const std::filesystem::path& path, const NpyReadOptions& options) {
  const FileReader reader(path);
  return volume_of(header_of(reader, path.string(), options));
}

NpyVolume read_npy_part(const std::filesystem::path& path, std::int32_t z0, std::int32_t z1,
                        const NpyReadOptions& options) {
  const std::string name = path.string();
  const FileReader reader(path);
  NpyReadOptions o = options;
  o.rank = 3;
  const Header h = header_of(reader, name, o);
  if (z0 < 0 || z1 > h.dims.z || z0 >= z1)
    throw InvalidArgument(name + ": slices " + std::to_string(z0) + ".." + std::to_string(z1) +
                          " are not a part of the array's " + std::to_string(h.dims.z));
  const std::size_t size = static_cast<std::size_t>(h.type->size);
  const std::uint64_t X = static_cast<std::uint64_t>(h.dims.x),
                      Y = static_cast<std::uint64_t>(h.dims.y),
                      Z = static_cast<std::uint64_t>(h.dims.z),
                      nz = static_cast<std::uint64_t>(z1 - z0);
  const std::uint64_t part_bytes = X * Y * nz * size;
  // A C-order file is read one x-plane at a time, beside the part.
  const std::uint64_t plane_bytes = h.c_order ? Y * Z * size : 0;
  require_memory(part_bytes + plane_bytes, options.memory_limit_bytes, name,
                 "slices " + std::to_string(z0) + ".." + std::to_string(z1) + " of the array");
  NpyVolume v = volume_of(h);
  v.dims.z = z1 - z0;
  v.file_origin = {0, 0, z0};
  v.bytes.resize(static_cast<std::size_t>(part_bytes));
  if (!h.c_order) {
    reader.read_at(h.data_offset + static_cast<std::uint64_t>(z0) * X * Y * size,
                   static_cast<std::size_t>(part_bytes), v.bytes.data());
  } else {
    // The plane a[x, :, :] holds the part's values of that x in Y runs, at y * Z + (z0..z1). One
    // read of the span from the first run to the last is cheapest while the runs fill most of it;
    // a thin part reads each run by itself, so that P processes read the file once between them
    // rather than P times.
    const bool span = (Y - 1) * Z + nz <= 2 * Y * nz;
    std::vector<std::uint8_t> plane(static_cast<std::size_t>(span ? (Y - 1) * Z + nz : Y * nz) *
                                    size);
    for (std::uint64_t x = 0; x < X; ++x) {
      const std::uint64_t first =
          h.data_offset + (x * Y * Z + static_cast<std::uint64_t>(z0)) * size;
      if (span) {
        reader.read_at(first, plane.size(), plane.data());
      } else {
        for (std::uint64_t y = 0; y < Y; ++y)
          reader.read_at(first + y * Z * size, static_cast<std::size_t>(nz * size),
                         plane.data() + y * nz * size);
      }
      const std::uint64_t stride = span ? Z : nz;
      for (std::uint64_t y = 0; y < Y; ++y)
        for (std::uint64_t z = 0; z < nz; ++z)
          std::memcpy(v.bytes.data() + ((z * Y + y) * X + x) * size,
                      plane.data() + (y * stride + z) * size, size);
    }
  }
  finish_values(h, v.bytes);
  return v;
}

namespace {

// magic, version, length and the dict literal of a volume's shape and dtype, padded to 64 bytes.
std::vector<std::uint8_t> encode_header(const NpyVolume& v) {
  const DTypeInfo& d = info(v.dtype);
  if (v.components < 1) throw InvalidArgument("encode_npy: components must be >= 1");
  const std::string descr = std::string(d.size == 1 ? "|" : "<") + d.kind + std::to_string(d.size);
  if (v.rank < 1 || v.rank > 3 ||
      (v.rank < 3 && (v.dims.z != 1 || (v.rank == 1 && v.dims.y != 1) || v.components > 1)))
    throw InvalidArgument("encode_npy: an array of rank " + std::to_string(v.rank) +
                          " has its other dimensions 1");
  std::string shape = std::to_string(v.dims.x) + (v.rank == 1 ? "," : "");  // (N,) is a 1-tuple
  if (v.rank >= 2) shape += ", " + std::to_string(v.dims.y);
  if (v.rank == 3) shape += ", " + std::to_string(v.dims.z);
  if (v.components > 1) shape += ", " + std::to_string(v.components);
  std::string header =
      "{'descr': '" + descr + "', 'fortran_order': True, 'shape': (" + shape + "), }";
  // Pad with spaces so that magic + version + length + header + '\n' is a multiple of 64.
  const bool v2 = header.size() + 11 > 65535;
  const std::size_t prefix = v2 ? 12 : 10;
  const std::size_t total = (prefix + header.size() + 1 + 63) / 64 * 64;
  header.append(total - prefix - header.size() - 1, ' ');
  header.push_back('\n');
  std::vector<std::uint8_t> out;
  out.reserve(total);
  const std::uint8_t magic[8] = {
      0x93, 'N', 'U', 'M', 'P', 'Y', static_cast<std::uint8_t>(v2 ? 2 : 1), 0};
  out.insert(out.end(), magic, magic + 8);
  const std::uint32_t len = static_cast<std::uint32_t>(header.size());
  out.push_back(static_cast<std::uint8_t>(len & 0xFF));
  out.push_back(static_cast<std::uint8_t>((len >> 8) & 0xFF));
  if (v2) {
    out.push_back(static_cast<std::uint8_t>((len >> 16) & 0xFF));
    out.push_back(static_cast<std::uint8_t>(len >> 24));
  }
  out.insert(out.end(), header.begin(), header.end());
  return out;
}

}  // namespace

std::vector<std::uint8_t> npy_header(DType dtype, Vec3i dims, int components) {
  NpyVolume shape_only{dtype, dims, {}, components};
  return encode_header(shape_only);
}

std::vector<std::uint8_t> encode_npy(const NpyVolume& v) {
  const std::size_t expect = static_cast<std::size_t>(v.count()) *
                             static_cast<std::size_t>(std::max(v.components, 0)) *
                             dtype_size(v.dtype);
  std::vector<std::uint8_t> out = encode_header(v);
  if (v.bytes.size() != expect) {
    throw InvalidArgument("encode_npy: volume holds " + std::to_string(v.bytes.size()) +
                          " bytes, expected " + std::to_string(expect));
  }
  out.insert(out.end(), v.bytes.begin(), v.bytes.end());
  return out;
}

void write_npy(const NpyVolume& volume, const std::filesystem::path& path) {
  write_file_atomic(path, encode_npy(volume));
}

World world_from_npy(const NpyVolume& v, const std::string& name, int chunk_edge,
                     std::uint64_t memory_limit_bytes) {
  World world(chunk_edge);
  // The dense materials, then the grid (at most one byte per voxel of the chunks it covers).
  const Box3i box = Box3i::from_size(v.dims);
  const std::uint64_t chunk_edge_u = static_cast<std::uint64_t>(chunk_edge);
  std::uint64_t chunk_voxels = 1;
  for (int k = 0; k < 3; ++k) {
    // The chunks the values cover, from a part's place in the whole array (which may start
    // inside a chunk).
    const std::uint64_t lo = static_cast<std::uint64_t>(v.file_origin[k]) / chunk_edge_u;
    const std::uint64_t hi = (static_cast<std::uint64_t>(v.file_origin[k]) +
                              static_cast<std::uint64_t>(v.dims[k]) + chunk_edge_u - 1) /
                             chunk_edge_u;
    chunk_voxels = mul_sat(chunk_voxels, (hi - lo) * chunk_edge_u);
  }
  require_memory(add_sat(dense_bytes(box, 1), chunk_voxels), memory_limit_bytes, name,
                 "a world of " + std::to_string(v.dims.x) + " x " + std::to_string(v.dims.y) +
                     " x " + std::to_string(v.dims.z) + " voxels");
  std::vector<std::uint8_t> materials(static_cast<std::size_t>(v.count()));
  for (std::int64_t i = 0; i < v.count(); ++i) {
    const double m = v.value(i);
    if (!(m >= 0 && m <= 255 && std::floor(m) == m)) {
      const Vec3i a = v.file_index_of(i);
      throw FormatError(name, v.file_offset_of(i),
                        "element a[" + std::to_string(a.x) + ", " + std::to_string(a.y) + ", " +
                            std::to_string(a.z) + "] holds " + number_text(m) +
                            ", not a material index (an integer 0..255)");
    }
    materials[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(m);
  }
  world.voxels.copy_from_dense(Box3i{v.file_origin, v.file_origin + v.dims}, materials.data());
  return world;
}

NpyVolume npy_from_world(const World& world, const Box3i& box) {
  if (box.empty()) throw InvalidArgument("npy_from_world: empty box " + to_string(box));
  NpyVolume v{DType::kUInt8, box.size(), {}, 1};
  v.bytes.resize(static_cast<std::size_t>(box.volume()));
  world.voxels.copy_to_dense(box, v.bytes.data());
  return v;
}

}  // namespace voxfield
