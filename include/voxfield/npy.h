// voxfield — NumPy .npy volumes.
//
// Reads format versions 1.0, 2.0 and 3.0 with dtypes bool, int8, uint8, int16, uint16, int32,
// uint32, int64 (NumPy's default integer), uint64, float32 and float64, either byte order, C or
// Fortran order. A volume is a 3-D array indexed a[x, y, z]; in memory voxfield keeps it x fastest
// (Fortran order), which is also how it writes it, so that reading back in NumPy gives the same
// a[x, y, z]. Each dimension is 1..2^29 (the coordinate range, box.h). Refused with a FormatError:
// other shapes and dtypes, a header key given twice, data shorter than the shape needs, and bytes
// after the data (NumPy never writes them; they mean a damaged or concatenated file). A volume
// whose decoded size passes the memory limit (limits.h) is refused with ResourceLimitError before
// anything is allocated for it.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "voxfield/world.h"

namespace voxfield {

enum class DType {
  kBool,
  kInt8,
  kUInt8,
  kInt16,
  kUInt16,
  kInt32,
  kUInt32,
  kInt64,
  kUInt64,
  kFloat32,
  kFloat64
};

std::size_t dtype_size(DType t);
const char* dtype_name(DType t);  // NumPy's name: "bool", "uint8", "float32", ...

// A dense 3-D volume of one dtype: dims.x * dims.y * dims.z values, x fastest, native byte order.
struct NpyVolume {
  DType dtype = DType::kUInt8;
  Vec3i dims;
  std::vector<std::uint8_t> bytes;
  // Values per voxel. Above 1 the array is 4-D, a[x, y, z, c], stored with the component slowest
  // (Fortran order): bytes hold `components` whole volumes one after another. Written only;
  // parse_npy reads 3-D volumes.
  int components = 1;
  // Dimensions of the array in the file: 3, or 1 or 2 for arrays a[x] / a[x, y] held with the
  // missing dimensions 1 (point lists, per-point values). Read when NpyReadOptions::rank asks.
  int rank = 3;
  // Where the data came from, for error messages: the byte offset of the array data in the file
  // and whether the file stored it in C order (z fastest). Zero / false for volumes built in code.
  std::uint64_t file_data_offset = 0;
  bool file_c_order = false;
  // A part of a file's array (read_npy_part): the index of this volume's first value in the file's
  // array, and the whole array's dimensions (zero when the volume is the whole array).
  Vec3i file_origin{};
  Vec3i file_dims{};

  std::int64_t count() const { return Box3i::from_size(dims).volume(); }
  // Value i (x fastest) converted to double, whatever the dtype.
  double value(std::int64_t i) const;
  // Byte offset in the file of value i (x fastest), following the file's order.
  std::uint64_t file_offset_of(std::int64_t i) const;
  // The index in the file's array of value i: a[x, y, z].
  Vec3i file_index_of(std::int64_t i) const;
};

struct NpyReadOptions {
  std::uint64_t memory_limit_bytes = 0;  // 0: the process default (limits.h)
  // The number of dimensions the array must have (1..3); fewer than 3 are read with the missing
  // dimensions 1, so a C-order (N, 3) array of points gives dims (N, 3, 1) and value(n + N c).
  int rank = 3;
};

NpyVolume parse_npy(std::span<const std::uint8_t> bytes, const std::string& name,
                    const NpyReadOptions& options = {});
NpyVolume read_npy(const std::filesystem::path& path, const NpyReadOptions& options = {});
// The header of a .npy file, checked against the file's size as read_npy checks it: a volume with
// its dtype, dims and file layout but no values. With read_npy_part, an array larger than one
// process may hold is read a part at a time (voxfield-mpi).
NpyVolume read_npy_header(const std::filesystem::path& path, const NpyReadOptions& options = {});
// The slices z0..z1 (0 <= z0 < z1 <= dims.z) of the 3-D array of a .npy file: dims (X, Y, z1 - z0),
// x fastest, the values read_npy gives for those slices, with file_origin (0, 0, z0) and file_dims
// the whole array's. Only the part is held: a Fortran-order file is read in one piece, a C-order
// one (z fastest) one x-plane at a time. The memory limit applies to the part. Throws what
// read_npy throws, and InvalidArgument for slices outside the array.
NpyVolume read_npy_part(const std::filesystem::path& path, std::int32_t z0, std::int32_t z1,
                        const NpyReadOptions& options = {});
// The values as float32 samples, x fastest (what the meshers take): FormatError naming `path` and
// the value's byte offset in the file for a value past float32's range. NaN passes on (the meshers
// refuse it by its place in the volume).
std::vector<float> float_samples(const NpyVolume& volume, const std::string& path);
// Encodes as format 1.0 (2.0 when the header needs it), Fortran order, little-endian.
std::vector<std::uint8_t> encode_npy(const NpyVolume& volume);
// The header encode_npy writes before the values of a 3-D array (dims, then `components` when
// above 1), for writers that put the values in place themselves: the values follow it, x fastest,
// component slowest, little-endian.
std::vector<std::uint8_t> npy_header(DType dtype, Vec3i dims, int components = 1);
void write_npy(const NpyVolume& volume, const std::filesystem::path& path);

// Builds a volume from dense values (x fastest). T must match dtype's size.
template <class T>
NpyVolume make_npy(DType dtype, Vec3i dims, const T* values) {
  if (sizeof(T) != dtype_size(dtype))
    throw InvalidArgument("make_npy: element size does not match dtype");
  NpyVolume v{dtype, dims, {}, 1};
  v.bytes.resize(static_cast<std::size_t>(v.count()) * sizeof(T));
  std::memcpy(v.bytes.data(), values, v.bytes.size());
  return v;
}

// Volume -> World: every non-zero value is that material, placed with a[x, y, z] at voxel (x, y,
// z) (for a part of a file's array, a[x, y, z] indexes the whole array: file_index_of). Throws
// FormatError naming the element a[x, y, z] and its byte offset in the file when a value is not an
// integer in 0..255 (bool counts as material 1), ResourceLimitError when the world would pass the
// memory limit.
World world_from_npy(const NpyVolume& volume, const std::string& name,
                     int chunk_edge = Grid<std::uint8_t>::kDefaultChunkEdge,
                     std::uint64_t memory_limit_bytes = 0);
// World -> uint8 volume of the materials in `box` (a[x, y, z] is voxel box.begin + (x, y, z)).
NpyVolume npy_from_world(const World& world, const Box3i& box);

}  // namespace voxfield
