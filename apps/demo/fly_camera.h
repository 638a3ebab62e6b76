// voxfield-demo — a fly camera: position, yaw and pitch (z up, as in MagicaVoxel).
#pragma once

#include <algorithm>
#include <cmath>

#include "voxfield/render.h"

namespace voxfield::demo {

struct FlyCamera {
  Vec3d eye{0, 0, 0};
  double yaw_rad = 0;    // about +z, 0 looking along +x
  double pitch_rad = 0;  // above the horizon, within +-89 degrees
  double fov_degrees = 60;

  Vec3d forward() const {
    return {std::cos(pitch_rad) * std::cos(yaw_rad), std::cos(pitch_rad) * std::sin(yaw_rad),
            std::sin(pitch_rad)};
  }
  Vec3d right() const { return Vec3d{std::sin(yaw_rad), -std::cos(yaw_rad), 0}; }

  Camera camera() const {
    Camera c;
    c.eye = eye;
    c.target = eye + forward();
    c.up = {0, 0, 1};
    c.fov_degrees = fov_degrees;
    return c;
  }

  // Looks at `target` from `from`.
  void look(const Vec3d& from, const Vec3d& target) {
    eye = from;
    const Vec3d d = target - from;
    yaw_rad = std::atan2(d.y, d.x);
    pitch_rad = std::atan2(d.z, std::sqrt(d.x * d.x + d.y * d.y));
  }

  void turn(double dyaw_rad, double dpitch_rad) {
    constexpr double kLimit = 89.0 * 3.14159265358979323846 / 180.0;
    yaw_rad += dyaw_rad;
    pitch_rad = std::clamp(pitch_rad + dpitch_rad, -kLimit, kLimit);
  }
};

}  // namespace voxfield::demo
