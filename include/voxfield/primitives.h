// voxfield — exact signed distance functions of analytic shapes (negative inside), and their
// closed-form volume and area: the shapes meshers are tested on and models are built from.
//
// The distances are Euclidean and exact everywhere (not bounds), after the standard derivations
// collected by Inigo Quilez ("3D SDFs", iquilezles.org): a box's distance splits into the part
// outside (the length of the positive excess) and inside (the largest negative excess).
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include "voxfield/box.h"

namespace voxfield::sdf {

// Sphere of `radius` centred at the origin.
inline double sphere(Vec3d p, double radius) {
  return p.length() - radius;
}

// Axis-aligned box centred at the origin with half extents `half`.
inline double box(Vec3d p, Vec3d half) {
  const Vec3d q{std::abs(p.x) - half.x, std::abs(p.y) - half.y, std::abs(p.z) - half.z};
  const Vec3d outside{std::max(q.x, 0.0), std::max(q.y, 0.0), std::max(q.z, 0.0)};
  return outside.length() + std::min(std::max(q.x, std::max(q.y, q.z)), 0.0);
}

// Torus around the z axis: the circle of radius `major` in the xy plane, thickened by `minor`.
inline double torus(Vec3d p, double major, double minor) {
  const double ring = std::sqrt(p.x * p.x + p.y * p.y) - major;
  return std::sqrt(ring * ring + p.z * p.z) - minor;
}

// Capsule: the segment a-b thickened by `radius`.
inline double capsule(Vec3d p, Vec3d a, Vec3d b, double radius) {
  const Vec3d pa = p - a, ba = b - a;
  const double len2 = dot(ba, ba);  // a == b: a sphere
  const double h = len2 > 0 ? std::clamp(dot(pa, ba) / len2, 0.0, 1.0) : 0.0;
  return (pa - ba * h).length() - radius;
}

// Closed-form measures, for checking meshes.
inline double sphere_volume(double r) {
  return 4.0 / 3.0 * std::numbers::pi * r * r * r;
}
inline double sphere_area(double r) {
  return 4.0 * std::numbers::pi * r * r;
}
inline double torus_volume(double major, double minor) {
  return 2.0 * std::numbers::pi * std::numbers::pi * major * minor * minor;
}
inline double torus_area(double major, double minor) {
  return 4.0 * std::numbers::pi * std::numbers::pi * major * minor;
}
inline double capsule_volume(double length, double r) {
  return std::numbers::pi * r * r * (length + 4.0 / 3.0 * r);
}
inline double capsule_area(double length, double r) {
  return 2.0 * std::numbers::pi * r * (length + 2.0 * r);
}

}  // namespace voxfield::sdf
