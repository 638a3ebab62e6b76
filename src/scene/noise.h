// voxfield — integer-hash value noise for the scene generators (internal).
//
// Value noise (lattice values from a hash, smoothstep-interpolated) summed over octaves (fBm).
// Hash-based rather than table-based so that every coordinate is independent of evaluation order,
// which keeps parallel generation deterministic.
#pragma once

#include <cmath>
#include <cstdint>

namespace voxfield::detail {

// SplitMix64 finaliser: a fast, well-mixed 64-bit hash.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

inline std::uint64_t hash3(std::uint64_t seed, std::int64_t x, std::int64_t y, std::int64_t z) {
  std::uint64_t h = mix64(seed ^ static_cast<std::uint64_t>(x));
  h = mix64(h ^ static_cast<std::uint64_t>(y));
  return mix64(h ^ static_cast<std::uint64_t>(z));
}

// Uniform in [0, 1).
inline double unit(std::uint64_t h) {
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

inline double smooth(double t) {
  return t * t * (3.0 - 2.0 * t);
}

// Value noise in [-1, 1] on a unit lattice.
inline double value_noise3(std::uint64_t seed, double x, double y, double z) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy),
             iz = static_cast<std::int64_t>(fz);
  const double tx = smooth(x - fx), ty = smooth(y - fy), tz = smooth(z - fz);
  double c[2][2][2];
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx)
        c[dz][dy][dx] = unit(hash3(seed, ix + dx, iy + dy, iz + dz)) * 2.0 - 1.0;
  auto lerp = [](double a, double b, double t) { return a + (b - a) * t; };
  const double y0 = lerp(lerp(c[0][0][0], c[0][0][1], tx), lerp(c[0][1][0], c[0][1][1], tx), ty);
  const double y1 = lerp(lerp(c[1][0][0], c[1][0][1], tx), lerp(c[1][1][0], c[1][1][1], tx), ty);
  return lerp(y0, y1, tz);
}

inline double value_noise2(std::uint64_t seed, double x, double y) {
  return value_noise3(seed, x, y, 0.0);
}

// Fractal sum of `octaves` octaves, each twice the frequency and half the amplitude; about [-1, 1].
inline double fbm3(std::uint64_t seed, double x, double y, double z, int octaves) {
  double sum = 0, amp = 1, norm = 0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * value_noise3(seed + static_cast<std::uint64_t>(o) * 0x51ED27ull, x, y, z);
    norm += amp;
    amp *= 0.5;
    x *= 2;
    y *= 2;
    z *= 2;
  }
  return sum / norm;
}

inline double fbm2(std::uint64_t seed, double x, double y, int octaves) {
  return fbm3(seed, x, y, 0.5, octaves);
}

}  // namespace voxfield::detail
