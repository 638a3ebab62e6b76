// voxfield — a .npy volume's samples as the floats the meshers take (see voxfield/npy.h).
//
// NpyVolume::value's conversion, one loop per dtype rather than a switch per sample: a 140 MB
// scan spent longer converting its samples that way than meshing them.
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/npy.h"

namespace voxfield {

namespace {

template <class T>
double sample(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

// float_samples for one dtype (bool as 0 or 1, like value()).
template <class T>
void convert_samples(const NpyVolume& volume, const std::string& path, std::vector<float>& out) {
  const std::uint8_t* p = volume.bytes.data();
  for (std::size_t i = 0; i < out.size(); ++i) {
    const double v =
        volume.dtype == DType::kBool ? (p[i] ? 1.0 : 0.0) : sample<T>(p + i * sizeof(T));
    if (std::abs(v) > std::numeric_limits<float>::max())  // false for NaN, which passes on
      throw FormatError(path, volume.file_offset_of(static_cast<std::int64_t>(i)),
                        "value " + std::to_string(v) + " does not fit a float32 sample");
    out[i] = static_cast<float>(v);
  }
}

}  // namespace

std::vector<float> float_samples(const NpyVolume& volume, const std::string& path) {
  std::vector<float> values(static_cast<std::size_t>(volume.count()));
  switch (volume.dtype) {
    case DType::kBool:
    case DType::kUInt8:
      convert_samples<std::uint8_t>(volume, path, values);
      break;
    case DType::kInt8:
      convert_samples<std::int8_t>(volume, path, values);
      break;
    case DType::kInt16:
      convert_samples<std::int16_t>(volume, path, values);
      break;
    case DType::kUInt16:
      convert_samples<std::uint16_t>(volume, path, values);
      break;
    case DType::kInt32:
      convert_samples<std::int32_t>(volume, path, values);
      break;
    case DType::kUInt32:
      convert_samples<std::uint32_t>(volume, path, values);
      break;
    case DType::kInt64:
      convert_samples<std::int64_t>(volume, path, values);
      break;
    case DType::kUInt64:
      convert_samples<std::uint64_t>(volume, path, values);
      break;
    case DType::kFloat32:
      convert_samples<float>(volume, path, values);
      break;
    case DType::kFloat64:
      convert_samples<double>(volume, path, values);
      break;
  }
  return values;
}

}  // namespace voxfield
