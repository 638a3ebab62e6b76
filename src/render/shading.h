// voxfield render — the light every renderer shares: palette albedo in linear light under a sun
// and a sky dome, exposure and sRGB encoding (the voxel renderer, the mesh rasteriser's shading and
// the CSG sphere tracer look alike).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "voxfield/box.h"

namespace voxfield::render_detail {

// An 8-bit sRGB channel in linear light.
inline float srgb_to_linear(std::uint8_t c) {
  const double v = c / 255.0;
  return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

struct Rgb {
  double r = 0, g = 0, b = 0;
  friend Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
  friend Rgb operator*(Rgb a, double s) { return {a.r * s, a.g * s, a.b * s}; }
  friend Rgb operator*(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
};
inline Rgb mix(Rgb a, Rgb b, double t) {
  return a * (1 - t) + b * t;
}

// Linear light of the sky and the sun (before exposure).
constexpr Rgb kSunLight{2.4, 2.2, 1.9};
constexpr Rgb kSkyZenith{0.22, 0.38, 0.78};
constexpr Rgb kSkyHorizon{0.70, 0.80, 0.92};
constexpr Rgb kGround{0.42, 0.45, 0.50};
constexpr Rgb kSkyAmbient{0.42, 0.52, 0.70};

inline Rgb sky(const Vec3d& dir) {
  const double z = dir.z;
  if (z < 0) return mix(kSkyHorizon, kGround, std::min(1.0, -z * 3));
  return mix(kSkyHorizon, kSkyZenith, std::pow(z, 0.6));
}
// The sky along a ray of direction `dir` (voxels) of a camera whose projector's sky_scale is
// `scale` (Camera::Projector): for a camera placed in non-cubic voxels, the sky of the world ray's
// direction along the voxel axes.
inline Rgb sky(const Vec3d& dir, const Vec3d& scale) {
  if (scale == Vec3d{1, 1, 1}) return sky(dir);
  return sky(Vec3d{dir.x * scale.x, dir.y * scale.y, dir.z * scale.z}.normalized());
}

// Exposure (1 - exp(-1.25 x)) then sRGB encoding, through one table over linear light in
// [0, kMaxLinear) — no exp or pow per pixel.
class ToneMap {
 public:
  ToneMap() {
    for (int i = 0; i < kSteps; ++i) {
      const double linear = kMaxLinear * i / (kSteps - 1);
      const double v = 1 - std::exp(-1.25 * linear);
      const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1 / 2.4) - 0.055;
      table_[static_cast<std::size_t>(i)] =
          static_cast<std::uint8_t>(std::lround(std::clamp(s, 0.0, 1.0) * 255));
    }
  }
  std::uint8_t encode(double linear) const {
    const double x = std::clamp(linear, 0.0, kMaxLinear) * ((kSteps - 1) / kMaxLinear);
    return table_[static_cast<std::size_t>(x + 0.5)];
  }
  void write(Rgb c, std::uint8_t* px) const {
    px[0] = encode(c.r);
    px[1] = encode(c.g);
    px[2] = encode(c.b);
  }

 private:
  static constexpr int kSteps = 16384;
  static constexpr double kMaxLinear = 8;  // exposes to 0.99995: white
  std::array<std::uint8_t, kSteps> table_{};
};
inline const ToneMap& tone_map() {
  static const ToneMap t;
  return t;
}

// A perceptual heat ramp (dark blue, blue, green, yellow, red) for x in [0, 1], as sRGB bytes.
inline void heat(double x, std::uint8_t* px) {
  static constexpr double kStops[5][3] = {
      {20, 12, 70}, {30, 100, 220}, {40, 190, 130}, {245, 215, 50}, {215, 40, 30}};
  x = std::clamp(x, 0.0, 1.0) * 4;
  const int i = std::min(3, static_cast<int>(x));
  const double f = x - i;
  for (int c = 0; c < 3; ++c)
    px[c] = static_cast<std::uint8_t>(std::lround(kStops[i][c] * (1 - f) + kStops[i + 1][c] * f));
}

// The distance view's pixel where its ray enters the cut plane on an air voxel: the skip field's
// stored value there (times inv_scale: voxels) on the heat ramp up to heat_max, with a darker band
// every 8 voxels of distance.
inline void cut_plane_heat(std::uint8_t stored, double inv_scale, double heat_max,
                           std::uint8_t* px) {
  heat(stored * inv_scale / heat_max, px);
  if (static_cast<int>(stored * inv_scale) % 8 == 0)
    for (int c = 0; c < 3; ++c) px[c] = static_cast<std::uint8_t>(px[c] * 3 / 4);
}

}  // namespace voxfield::render_detail
