// Vector textures in three storages (docs/vectors.md, "Storage"): the paper's RGBA8 with its
// rounding defined, IEEE half floats (rounded to nearest even) and floats.
#include <bit>
#include <cmath>
#include <cstring>

#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/vectors.h"

namespace voxfield {
namespace {

std::uint8_t unorm8(double v) {  // v in [0, 1]
  return static_cast<std::uint8_t>(std::floor(std::clamp(v, 0.0, 1.0) * 255.0 + 0.5));
}

// float -> IEEE binary16, round to nearest even; overflow to infinity, NaN kept NaN.
std::uint16_t to_half(float f) {
  const std::uint32_t x = std::bit_cast<std::uint32_t>(f);
  const std::uint16_t sign = static_cast<std::uint16_t>((x >> 16) & 0x8000u);
  const std::uint32_t abs = x & 0x7fffffffu;
  if (abs >= 0x7f800000u) return sign | (abs > 0x7f800000u ? 0x7e00u : 0x7c00u);
  if (abs >= 0x477ff000u) return sign | 0x7c00u;  // rounds to beyond the largest half: infinity
  if (abs < 0x38800000u) {                         // below the smallest normal half: subnormal
    const float scaled = std::bit_cast<float>(abs) * 16777216.0f;  // * 2^24: units of 2^-24
    return sign | static_cast<std::uint16_t>(std::nearbyint(scaled));  // nearest even (default mode)
  }
  const std::uint32_t mantissa_odd = (abs >> 13) & 1u;
  const std::uint32_t rounded = abs + 0xfffu + mantissa_odd;  // round half to even at bit 13
  return sign | static_cast<std::uint16_t>((rounded - 0x38000000u) >> 13);
}

float from_half(std::uint16_t h) {
  const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000u) << 16;
  const std::uint32_t exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
  if (exponent == 0) {
    const float v = static_cast<float>(mantissa) / 16777216.0f;  // * 2^-24
    return sign ? -v : v;
  }
  if (exponent == 31) return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));
  return std::bit_cast<float>(sign | ((exponent + 112) << 23) | (mantissa << 13));
}

}  // namespace

VectorTexture::VectorTexture(Vec3i resolution, VectorStorage storage)
    : resolution_(resolution), storage_(storage) {
  for (int a = 0; a < 3; ++a)
    if (resolution[a] < 1 || resolution[a] > 4096)
      throw InvalidArgument("vector texture: the resolution must be 1..4096 on every axis (got " +
                            to_string(resolution) + ")");
  const std::uint64_t need =
      dense_bytes(Box3i::from_size(resolution), static_cast<std::uint64_t>(bytes_per_texel()));
  require_memory(need, 0, "vector texture " + to_string(resolution),
                 std::string("its ") + vector_storage_name(storage) + " texels");
  bytes_.assign(static_cast<std::size_t>(need), 0);
  clear();
}

int VectorTexture::bytes_per_texel() const {
  return storage_ == VectorStorage::kRgba8 ? 4 : storage_ == VectorStorage::kRgba16f ? 8 : 16;
}

void VectorTexture::clear() {
  if (storage_ == VectorStorage::kRgba8) {
    for (std::size_t i = 0; i < bytes_.size(); i += 4) {
      bytes_[i] = bytes_[i + 1] = bytes_[i + 2] = 128;
      bytes_[i + 3] = 0;
    }
  } else {
    std::fill(bytes_.begin(), bytes_.end(), std::uint8_t{0});
  }
}

VectorTexel VectorTexture::get(std::int64_t index) const {
  const std::uint8_t* p = bytes_.data() + index * bytes_per_texel();
  switch (storage_) {
    case VectorStorage::kRgba8:
      return {static_cast<float>(p[0] * (2.0 / 255.0) - 1.0),
              static_cast<float>(p[1] * (2.0 / 255.0) - 1.0),
              static_cast<float>(p[2] * (2.0 / 255.0) - 1.0), static_cast<float>(p[3] / 255.0)};
    case VectorStorage::kRgba16f: {
      std::uint16_t h[4];
      std::memcpy(h, p, 8);
      return {from_half(h[0]), from_half(h[1]), from_half(h[2]), from_half(h[3])};
    }
    case VectorStorage::kRgba32f: {
      VectorTexel t;
      std::memcpy(&t, p, 16);
      return t;
    }
  }
  return {};
}

void VectorTexture::set(std::int64_t index, const VectorTexel& t) {
  std::uint8_t* p = bytes_.data() + index * bytes_per_texel();
  switch (storage_) {
    case VectorStorage::kRgba8:
      p[0] = unorm8((t.x + 1.0) / 2.0);
      p[1] = unorm8((t.y + 1.0) / 2.0);
      p[2] = unorm8((t.z + 1.0) / 2.0);
      p[3] = unorm8(t.strength);
      return;
    case VectorStorage::kRgba16f: {
      const std::uint16_t h[4] = {to_half(t.x), to_half(t.y), to_half(t.z), to_half(t.strength)};
      std::memcpy(p, h, 8);
      return;
    }
    case VectorStorage::kRgba32f:
      std::memcpy(p, &t, 16);
      return;
  }
}

VectorTexel VectorTexture::quantize(const VectorTexel& texel, VectorStorage storage) {
  VectorTexture one(Vec3i{1, 1, 1}, storage);
  one.set(0, texel);
  return one.get(0);
}

}  // namespace voxfield
