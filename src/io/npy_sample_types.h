// voxfield — a .npy dtype's samples as C++ types (internal to the io layer: npy.cpp's
// NpyVolume::value and npy_samples.cpp's float_samples share the one mapping).
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>

#include "voxfield/npy.h"

namespace voxfield::detail::npy {

// The type of a bool array's samples: one byte, any value but 0 true (as NumPy reads it).
struct BoolSample {};

// The sample of type T at p as a double.
template <class T>
double sample_as_double(const std::uint8_t* p) {
  if constexpr (std::is_same_v<T, BoolSample>) {
    return *p ? 1.0 : 0.0;
  } else {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  }
}

// f.template operator()<T>() with T the type of dtype t's samples, and its result: one switch
// on the dtype for a whole loop instead of one per sample.
template <class F>
decltype(auto) with_sample_type(DType t, F&& f) {
  switch (t) {
    case DType::kBool:
      return f.template operator()<BoolSample>();
    case DType::kInt8:
      return f.template operator()<std::int8_t>();
    case DType::kUInt8:
      return f.template operator()<std::uint8_t>();
    case DType::kInt16:
      return f.template operator()<std::int16_t>();
    case DType::kUInt16:
      return f.template operator()<std::uint16_t>();
    case DType::kInt32:
      return f.template operator()<std::int32_t>();
    case DType::kUInt32:
      return f.template operator()<std::uint32_t>();
    case DType::kInt64:
      return f.template operator()<std::int64_t>();
    case DType::kUInt64:
      return f.template operator()<std::uint64_t>();
    case DType::kFloat32:
      return f.template operator()<float>();
    case DType::kFloat64:
      break;
  }
  return f.template operator()<double>();
}

}  // namespace voxfield::detail::npy
