// voxfield — integer voxel coordinates and boxes.
//
// Coordinates are signed 32-bit voxel indices. A Box3i is half-open: it holds the voxels p with
// begin <= p < end on every axis (so its extent is end - begin, and an empty box has
// end <= begin on some axis).
//
// The supported range (docs/limits.md): every voxel a grid stores, every grid bound and every
// coordinate a file may carry lies in kCoordRange, -2^29 <= p < 2^29 on each axis. Extents of
// boxes inside it fit in 31 bits with room to grow a box by any clamp without overflow, so
// size() of such a box is exact; readers and grids refuse anything outside. For boxes outside
// the range size() and volume() still never overflow: they are computed in 64 (128) bits and
// saturate at INT32_MAX / INT64_MAX.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
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
  Vec3d normalized() const {
    const double l = length();
    return {x / l, y / l, z / l};
  }
};

// The supported coordinate range: -kCoordLimit <= p < kCoordLimit on every axis.
inline constexpr std::int32_t kCoordLimit = std::int32_t{1} << 29;

// Whether v lies in the supported range (voxel coordinates) / whether a box bound does (a box's
// end may equal kCoordLimit).
constexpr bool coord_in_range(std::int64_t v) {
  return v >= -kCoordLimit && v < kCoordLimit;
}
constexpr bool bound_in_range(std::int64_t v) {
  return v >= -kCoordLimit && v <= kCoordLimit;
}

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
  // Extent along one axis in 64 bits; zero (never negative) for an empty box.
  constexpr std::int64_t extent(int axis) const {
    return std::max<std::int64_t>(0, std::int64_t{end[axis]} - begin[axis]);
  }
  // Extent along each axis; zero (never negative) for an empty box. Exact for boxes inside
  // kCoordRange; saturates at INT32_MAX beyond it.
  constexpr Vec3i size() const {
    auto s = [&](int k) {
      return static_cast<std::int32_t>(std::min<std::int64_t>(extent(k), INT32_MAX));
    };
    return {s(0), s(1), s(2)};
  }
  // Number of voxels; saturates at INT64_MAX (a box of 2^29 on every side holds 2^87).
  constexpr std::int64_t volume() const {
    // Each extent is below 2^32, so the first product fits in 64 unsigned bits.
    const std::uint64_t xy =
        static_cast<std::uint64_t>(extent(0)) * static_cast<std::uint64_t>(extent(1));
    const std::uint64_t z = static_cast<std::uint64_t>(extent(2));
    if (z != 0 && xy > static_cast<std::uint64_t>(INT64_MAX) / z) return INT64_MAX;
    return static_cast<std::int64_t>(xy * z);
  }
  // Whether every bound lies in the supported range (an empty box always does).
  constexpr bool in_range() const {
    if (empty()) return true;
    for (int k = 0; k < 3; ++k)
      if (!bound_in_range(begin[k]) || !bound_in_range(end[k])) return false;
    return true;
  }
  constexpr bool contains(Vec3i p) const {
    return p.x >= begin.x && p.x < end.x && p.y >= begin.y && p.y < end.y && p.z >= begin.z &&
           p.z < end.z;
  }
  // True when every voxel of `other` lies in this box (an empty `other` is contained anywhere).
  constexpr bool contains(const Box3i& other) const {
    return other.empty() ||
           (other.begin.x >= begin.x && other.end.x <= end.x && other.begin.y >= begin.y &&
            other.end.y <= end.y && other.begin.z >= begin.z && other.end.z <= end.z);
  }
  constexpr Box3i intersect(const Box3i& o) const {
    return {
        {std::max(begin.x, o.begin.x), std::max(begin.y, o.begin.y), std::max(begin.z, o.begin.z)},
        {std::min(end.x, o.end.x), std::min(end.y, o.end.y), std::min(end.z, o.end.z)}};
  }
  // Smallest box holding both; an empty operand is ignored.
  constexpr Box3i unite(const Box3i& o) const {
    if (empty()) return o;
    if (o.empty()) return *this;
    return {
        {std::min(begin.x, o.begin.x), std::min(begin.y, o.begin.y), std::min(begin.z, o.begin.z)},
        {std::max(end.x, o.end.x), std::max(end.y, o.end.y), std::max(end.z, o.end.z)}};
  }
  // The box grown by `voxels` on every side (shrunk when negative).
  constexpr Box3i grown(std::int32_t voxels) const {
    return {begin - Vec3i::splat(voxels), end + Vec3i::splat(voxels)};
  }
  friend constexpr bool operator==(const Box3i& a, const Box3i& b) = default;
};

// Hash of a coordinate for unordered containers (chunk maps, sets of chunks).
struct Vec3iHash {
  std::size_t operator()(const Vec3i& c) const noexcept {
    std::uint64_t h = static_cast<std::uint32_t>(c.x) * 0x9E3779B185EBCA87ull;
    h ^= static_cast<std::uint32_t>(c.y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
    h ^= static_cast<std::uint32_t>(c.z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
    return static_cast<std::size_t>(h ^ (h >> 29));
  }
};

inline constexpr Box3i kCoordRange{Vec3i::splat(-kCoordLimit), Vec3i::splat(kCoordLimit)};

inline std::string to_string(const Box3i& b) {
  // Appended piece by piece: GCC 12 misreads "[" + std::string&& as a huge copy
  // (-Wstringop-overflow, a known false positive).
  std::string s = "[";
  s += to_string(b.begin);
  s += " .. ";
  s += to_string(b.end);
  s += ")";
  return s;
}

}  // namespace voxfield
