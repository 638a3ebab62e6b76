// Texel encodings, one struct per storage, inlined into the passes that sweep whole textures
// (the conversion and the fused step); VectorTexture::get/set dispatch to the same code, so a
// texel reads the same whichever path wrote it. docs/vectors.md, "Storage", defines them.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "voxfield/vectors.h"

namespace voxfield::detail::vectors {

// floor(v * 255 + 1/2) for v clamped to [0, 1], in float arithmetic (as a shader computes it;
// the truncating conversion is the floor of a non-negative value).
inline std::uint8_t unorm8(float v) {
  const float c = v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f;  // NaN reads 0, never reaches the cast
  return static_cast<std::uint8_t>(c * 255.0f + 0.5f);
}

// Decoded values of every byte: 2 b / 255 - 1 (directions) and b / 255 (strengths), as floats.
struct Rgba8Tables {
  std::array<float, 256> direction, strength;
  Rgba8Tables() {
    for (int b = 0; b < 256; ++b) {
      direction[b] = static_cast<float>(b * (2.0 / 255.0) - 1.0);
      strength[b] = static_cast<float>(b / 255.0);
    }
  }
};
inline const Rgba8Tables& rgba8_tables() {
  static const Rgba8Tables t;
  return t;
}

// float -> IEEE binary16, round to nearest even; overflow to infinity, NaN kept NaN.
inline std::uint16_t to_half(float f) {
  const std::uint32_t x = std::bit_cast<std::uint32_t>(f);
  const std::uint16_t sign = static_cast<std::uint16_t>((x >> 16) & 0x8000u);
  const std::uint32_t abs = x & 0x7fffffffu;
  if (abs >= 0x7f800000u) return sign | (abs > 0x7f800000u ? 0x7e00u : 0x7c00u);
  if (abs >= 0x477ff000u) return sign | 0x7c00u;  // rounds beyond the largest half: infinity
  if (abs < 0x38800000u) {                        // below the smallest normal half: subnormal
    const float scaled = std::bit_cast<float>(abs) * 16777216.0f;      // units of 2^-24, exact
    return sign | static_cast<std::uint16_t>(std::nearbyint(scaled));  // nearest even
  }
  const std::uint32_t odd = (abs >> 13) & 1u;
  return sign | static_cast<std::uint16_t>((abs + 0xfffu + odd - 0x38000000u) >> 13);
}

inline float from_half(std::uint16_t h) {
  const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000u) << 16;
  const std::uint32_t exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
  if (exponent == 0) {
    const float v = static_cast<float>(mantissa) / 16777216.0f;
    return sign ? -v : v;
  }
  if (exponent == 31) return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));
  return std::bit_cast<float>(sign | ((exponent + 112) << 23) | (mantissa << 13));
}

template <VectorStorage S>
struct Codec;

template <>
struct Codec<VectorStorage::kRgba8> {
  static constexpr int kBytes = 4;
  static VectorTexel load(const std::uint8_t* p) {
    const Rgba8Tables& t = rgba8_tables();
    return {t.direction[p[0]], t.direction[p[1]], t.direction[p[2]], t.strength[p[3]]};
  }
  static void store(std::uint8_t* p, const VectorTexel& v) {
    p[0] = unorm8((v.x + 1.0f) * 0.5f);
    p[1] = unorm8((v.y + 1.0f) * 0.5f);
    p[2] = unorm8((v.z + 1.0f) * 0.5f);
    p[3] = unorm8(v.strength);
  }
  static void store_zero(std::uint8_t* p) {
    static constexpr std::uint8_t kZero[4] = {128, 128, 128, 0};
    std::memcpy(p, kZero, 4);
  }
  static bool zero_strength(const std::uint8_t* p) { return p[3] == 0; }
};

template <>
struct Codec<VectorStorage::kRgba16f> {
  static constexpr int kBytes = 8;
  static VectorTexel load(const std::uint8_t* p) {
    std::uint16_t h[4];
    std::memcpy(h, p, 8);
    return {from_half(h[0]), from_half(h[1]), from_half(h[2]), from_half(h[3])};
  }
  static void store(std::uint8_t* p, const VectorTexel& v) {
    const std::uint16_t h[4] = {to_half(v.x), to_half(v.y), to_half(v.z), to_half(v.strength)};
    std::memcpy(p, h, 8);
  }
  static void store_zero(std::uint8_t* p) { std::memset(p, 0, 8); }
  static bool zero_strength(const std::uint8_t* p) {
    std::uint16_t h;
    std::memcpy(&h, p + 6, 2);
    return (h & 0x7fffu) == 0;
  }
};

template <>
struct Codec<VectorStorage::kRgba32f> {
  static constexpr int kBytes = 16;
  static VectorTexel load(const std::uint8_t* p) {
    VectorTexel t;
    std::memcpy(&t, p, 16);
    return t;
  }
  static void store(std::uint8_t* p, const VectorTexel& v) { std::memcpy(p, &v, 16); }
  static void store_zero(std::uint8_t* p) { std::memset(p, 0, 16); }
  static bool zero_strength(const std::uint8_t* p) {
    float s;
    std::memcpy(&s, p + 12, 4);
    return s == 0;
  }
};

// Calls f(Codec<S>{}) for the texture's storage.
template <class F>
decltype(auto) with_codec(VectorStorage s, F&& f) {
  switch (s) {
    case VectorStorage::kRgba8:
      return f(Codec<VectorStorage::kRgba8>{});
    case VectorStorage::kRgba16f:
      return f(Codec<VectorStorage::kRgba16f>{});
    case VectorStorage::kRgba32f:
      break;
  }
  return f(Codec<VectorStorage::kRgba32f>{});
}

}  // namespace voxfield::detail::vectors
