// voxfield — integer voxel coordinates and boxes.
//
// Coordinates are signed 32-bit voxel indices. A Box3i is half-open: it holds the voxels p with
// begin <= p < end on every axis (so its extent is end - begin, and an empty box has
// end <= begin on some axis). Sizes are computed in 64-bit so that boxes spanning most of the
// int32 range do not overflow.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace voxfield {

struct Vec3i {
  std::int32_t x = 0, y = 0, z = 0;

  constexpr std::int32_t operator[](int axis) const { return axis == 0 ? x : axis == 1 ? y : z; }
  constexpr std::int32_t& operator[](int axis) { return axis == 0 ? x : axis == 1 ? y : z; }
  friend constexpr bool operator==(const Vec3i&, const Vec3i&) = default;
  friend constexpr Vec3i operator+(Vec3i a, Vec3i b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3i operator-(Vec3i a, Vec3i b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  static constexpr Vec3i splat(std::int32_t v) { return {v, v, v}; }
};

inline std::string to_string(Vec3i v) {
  return std::to_string(v.x) + "," + std::to_string(v.y) + "," + std::to_string(v.z);
}

// A point or direction in voxel space (voxel v spans [v, v + 1) on each axis).
struct Vec3d {
  double x = 0, y = 0, z = 0;
  constexpr double operator[](int axis) const { return axis == 0 ? x : axis == 1 ? y : z; }
  constexpr double& operator[](int axis) { return axis == 0 ? x : axis == 1 ? y : z; }
  friend constexpr bool operator==(const Vec3d&, const Vec3d&) = default;
  friend constexpr Vec3d operator+(Vec3d a, Vec3d b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
  friend constexpr Vec3d operator-(Vec3d a, Vec3d b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
  friend constexpr Vec3d operator*(Vec3d a, double s) { return {a.x * s, a.y * s, a.z * s}; }
  friend constexpr double dot(Vec3d a, Vec3d b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
  friend constexpr Vec3d cross(Vec3d a, Vec3d b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
  }
  double length() const { return std::sqrt(x * x + y * y + z * z); }
  Vec3d normalized() const { const double l = length(); return {x / l, y / l, z / l}; }
};

struct Box3i {
  Vec3i begin;  // inclusive
  Vec3i end;    // exclusive

  // The box [0, size) — the usual shape of a dense volume.
  static constexpr Box3i from_size(Vec3i size) { return {{0, 0, 0}, size}; }
  // The box holding the voxels min..max inclusive on each axis.
  static constexpr Box3i from_inclusive(Vec3i min, Vec3i max) {
    return {min, {max.x + 1, max.y + 1, max.z + 1}};
  }

  constexpr bool empty() const { return end.x <= begin.x || end.y <= begin.y || end.z <= begin.z; }
  // Extent along each axis; zero (never negative) for an empty box.
  constexpr Vec3i size() const {
    return {std::max(0, end.x - begin.x), std::max(0, end.y - begin.y),
            std::max(0, end.z - begin.z)};
  }
  constexpr std::int64_t volume() const {
    const Vec3i s = size();
    return std::int64_t{s.x} * s.y * s.z;
  }
  constexpr bool contains(Vec3i p) const {
    return p.x >= begin.x && p.x < end.x && p.y >= begin.y && p.y < end.y && p.z >= begin.z &&
           p.z < end.z;
  }
  // True when every voxel of `other` lies in this box (an empty `other` is contained anywhere).
  constexpr bool contains(const Box3i& other) const {
    return other.empty() || (other.begin.x >= begin.x && other.end.x <= end.x &&
                             other.begin.y >= begin.y && other.end.y <= end.y &&
                             other.begin.z >= begin.z && other.end.z <= end.z);
  }
  constexpr Box3i intersect(const Box3i& o) const {
    return {{std::max(begin.x, o.begin.x), std::max(begin.y, o.begin.y), std::max(begin.z, o.begin.z)},
            {std::min(end.x, o.end.x), std::min(end.y, o.end.y), std::min(end.z, o.end.z)}};
  }
  // Smallest box holding both; an empty operand is ignored.
  constexpr Box3i unite(const Box3i& o) const {
    if (empty()) return o;
    if (o.empty()) return *this;
    return {{std::min(begin.x, o.begin.x), std::min(begin.y, o.begin.y), std::min(begin.z, o.begin.z)},
            {std::max(end.x, o.end.x), std::max(end.y, o.end.y), std::max(end.z, o.end.z)}};
  }
  // The box grown by `voxels` on every side (shrunk when negative).
  constexpr Box3i grown(std::int32_t voxels) const {
    return {begin - Vec3i::splat(voxels), end + Vec3i::splat(voxels)};
  }
  friend constexpr bool operator==(const Box3i& a, const Box3i& b) = default;
};

inline std::string to_string(const Box3i& b) {
  return "[" + to_string(b.begin) + " .. " + to_string(b.end) + ")";
}

}  // namespace voxfield
