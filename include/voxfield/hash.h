// voxfield — FNV-1a (64-bit), the content hash that benchmarks print beside their times
// (content_hash of a field, distance.h; of a frame, image.h): the same bytes hash the same on
// every machine, so results can be pinned and compared across builds.
#pragma once

#include <cstddef>
#include <cstdint>

namespace voxfield {

constexpr std::uint64_t kFnvOffset = 1469598103934665603ull;

// FNV-1a continued over `n` bytes from `h` (start from kFnvOffset).
inline std::uint64_t fnv1a(std::uint64_t h, const void* bytes, std::size_t n) {
  const auto* p = static_cast<const unsigned char*>(bytes);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 1099511628211ull;
  }
  return h;
}

}  // namespace voxfield
