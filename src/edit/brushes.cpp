// voxfield — brush shapes: which voxels a brush covers, and the box it may touch.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "voxfield/edit.h"

namespace voxfield {
namespace {

constexpr double kCoordLimit = 1 << 30;  // brushes are clamped to |coordinate| <= 2^30

int floor_coord(double v) {
  return static_cast<int>(std::floor(std::clamp(v, -kCoordLimit, kCoordLimit)));
}
int ceil_coord(double v) {
  return static_cast<int>(std::ceil(std::clamp(v, -kCoordLimit, kCoordLimit)));
}

Box3i box_around(const Vec3d& lo, const Vec3d& hi) {
  return Box3i::from_inclusive({ceil_coord(lo[0]), ceil_coord(lo[1]), ceil_coord(lo[2])},
                               {floor_coord(hi[0]), floor_coord(hi[1]), floor_coord(hi[2])});
}

using Mat3 = std::array<std::array<double, 3>, 3>;

// Rotation about x, then y, then z (angles in degrees): R = Rz * Ry * Rx.
Mat3 rotation(const Vec3d& deg) {
  const double k = 3.14159265358979323846 / 180.0;
  const double cx = std::cos(deg[0] * k), sx = std::sin(deg[0] * k);
  const double cy = std::cos(deg[1] * k), sy = std::sin(deg[1] * k);
  const double cz = std::cos(deg[2] * k), sz = std::sin(deg[2] * k);
  return {{{cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx},
           {sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx},
           {-sy, cy * sx, cy * cx}}};
}

struct Bounds {
  Box3i operator()(const SphereBrush& s) const {
    return box_around({s.center[0] - s.radius, s.center[1] - s.radius, s.center[2] - s.radius},
                      {s.center[0] + s.radius, s.center[1] + s.radius, s.center[2] + s.radius});
  }
  Box3i operator()(const BoxBrush& b) const { return Box3i::from_inclusive(b.min, b.max); }
  Box3i operator()(const RotatedBoxBrush& b) const {
    const Mat3 r = rotation(b.rotation_deg);
    // Half-size of the rotated box's axis-aligned bounds: sum of |R_ij| h_j.
    Vec3d lo, hi;
    for (int i = 0; i < 3; ++i) {
      double e = 0;
      for (int j = 0; j < 3; ++j) e += std::abs(r[i][j]) * b.half_extent[j];
      lo[i] = b.center[i] - e - 1e-9;
      hi[i] = b.center[i] + e + 1e-9;
    }
    return box_around(lo, hi);
  }
  Box3i operator()(const CapsuleBrush& c) const {
    Vec3d lo, hi;
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(c.a[i], c.b[i]) - c.radius;
      hi[i] = std::max(c.a[i], c.b[i]) + c.radius;
    }
    return box_around(lo, hi);
  }
  Box3i operator()(const StampBrush& s) const {
    if (!s.model) return {};
    const Box3i b = s.model->voxels.content_bounds();
    return b.empty() ? b : Box3i{b.begin + s.offset, b.end + s.offset};
  }
};

struct Contains {
  Vec3i p;
  bool operator()(const SphereBrush& s) const {
    const double dx = p.x - s.center[0], dy = p.y - s.center[1], dz = p.z - s.center[2];
    return dx * dx + dy * dy + dz * dz <= s.radius * s.radius;
  }
  bool operator()(const BoxBrush& b) const {
    return Box3i::from_inclusive(b.min, b.max).contains(p);
  }
  bool operator()(const RotatedBoxBrush& b) const {
    // Applying a brush tests thousands of voxels with one rotation: its matrix is kept per thread
    // for the last angles seen, compared bit for bit (the same function of the same bits).
    struct Cached {
      bool valid = false;
      Vec3d deg;
      Mat3 r;
    };
    thread_local Cached cached;
    if (!cached.valid || std::memcmp(&cached.deg, &b.rotation_deg, sizeof(Vec3d)) != 0) {
      cached.r = rotation(b.rotation_deg);
      cached.deg = b.rotation_deg;
      cached.valid = true;
    }
    const Mat3& r = cached.r;
    const Vec3d d{p.x - b.center[0], p.y - b.center[1], p.z - b.center[2]};
    for (int j = 0; j < 3; ++j) {
      // Coordinate along the box's axis j: column j of R dotted with d.
      const double q = r[0][j] * d[0] + r[1][j] * d[1] + r[2][j] * d[2];
      if (std::abs(q) > b.half_extent[j] + 1e-9) return false;
    }
    return true;
  }
  bool operator()(const CapsuleBrush& c) const {
    Vec3d ab, ap;
    double len2 = 0, dot = 0;
    for (int i = 0; i < 3; ++i) {
      ab[i] = c.b[i] - c.a[i];
      ap[i] = p[i] - c.a[i];
      len2 += ab[i] * ab[i];
      dot += ab[i] * ap[i];
    }
    const double t = len2 > 0 ? std::clamp(dot / len2, 0.0, 1.0) : 0.0;
    double d2 = 0;
    for (int i = 0; i < 3; ++i) {
      const double e = ap[i] - t * ab[i];
      d2 += e * e;
    }
    return d2 <= c.radius * c.radius;
  }
  bool operator()(const StampBrush& s) const {
    return s.model && s.model->voxels.get(p - s.offset) != 0;
  }
};

}  // namespace

Box3i brush_bounds(const Brush& brush) {
  return std::visit(Bounds{}, brush);
}

bool brush_contains(const Brush& brush, Vec3i p) {
  return std::visit(Contains{p}, brush);
}
bool brush_contains(const SphereBrush& b, Vec3i p) {
  return Contains{p}(b);
}
bool brush_contains(const BoxBrush& b, Vec3i p) {
  return Contains{p}(b);
}
bool brush_contains(const RotatedBoxBrush& b, Vec3i p) {
  return Contains{p}(b);
}
bool brush_contains(const CapsuleBrush& b, Vec3i p) {
  return Contains{p}(b);
}
bool brush_contains(const StampBrush& b, Vec3i p) {
  return Contains{p}(b);
}

}  // namespace voxfield
