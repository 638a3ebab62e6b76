// voxfield CSG — the shapes' distance functions in their own frames (double precision), shared by
// the model's reference evaluation and the compiled tapes, and the interval helpers clipping uses.
//
// Every shape but the ellipsoid is an exact Euclidean distance (Inigo Quilez, "3D SDFs",
// iquilezles.org, gives the derivations); the cone is derived here from its cross-section, a
// triangle in the (radius, z) half-plane. The tests check each against a brute-force distance to a
// dense sampling of the surface.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "voxfield/box.h"
#include "voxfield/csg.h"

namespace voxfield::csg::detail {

inline double len2d(double x, double y) {
  return std::sqrt(x * x + y * y);
}

// Distance in 2-D from q to the segment a-b.
inline double segment_distance_2d(double qx, double qy, double ax, double ay, double bx,
                                  double by) {
  const double px = qx - ax, py = qy - ay, ex = bx - ax, ey = by - ay;
  const double e2 = ex * ex + ey * ey;
  const double t = e2 > 0 ? std::clamp((px * ex + py * ey) / e2, 0.0, 1.0) : 0.0;
  return len2d(px - ex * t, py - ey * t);
}

inline double sd_sphere(Vec3d p, double r) {
  return p.length() - r;
}
inline double sd_box(Vec3d p, double hx, double hy, double hz) {
  const double qx = std::abs(p.x) - hx, qy = std::abs(p.y) - hy, qz = std::abs(p.z) - hz;
  const Vec3d out{std::max(qx, 0.0), std::max(qy, 0.0), std::max(qz, 0.0)};
  return out.length() + std::min(std::max(qx, std::max(qy, qz)), 0.0);
}
inline double sd_cylinder(Vec3d p, double r, double half_h) {
  const double dx = len2d(p.x, p.y) - r, dy = std::abs(p.z) - half_h;
  return std::min(std::max(dx, dy), 0.0) + len2d(std::max(dx, 0.0), std::max(dy, 0.0));
}
inline double sd_capsule(Vec3d p, double r, double half_h) {
  const double z = std::clamp(p.z, -half_h, half_h);
  return Vec3d{p.x, p.y, p.z - z}.length() - r;
}
inline double sd_torus(Vec3d p, double major, double minor) {
  return len2d(len2d(p.x, p.y) - major, p.z) - minor;
}
// The capped cone: in the (rho, z) half-plane its section is the triangle apex (0, h/2), base
// corner (r, -h/2), base centre (0, -h/2). The axis is no boundary of the solid, so the distance is
// the nearer of the slanted side and the base, negative inside the triangle.
inline double sd_cone(Vec3d p, double r, double half_h) {
  const double rho = len2d(p.x, p.y), z = p.z;
  const double side = segment_distance_2d(rho, z, 0, half_h, r, -half_h);
  const double base = segment_distance_2d(rho, z, r, -half_h, 0, -half_h);
  const double d = std::min(side, base);
  const bool inside = z >= -half_h && z <= half_h && rho * 2 * half_h <= r * (half_h - z);
  return inside ? -d : d;
}
inline double sd_plane(Vec3d p, double nx, double ny, double nz, double d) {
  return p.x * nx + p.y * ny + p.z * nz - d;
}
// k0 (k0 - 1) / k1 with k0 = |p / r|, k1 = |p / r^2|; at the centre, where both vanish, the limit
// along the shortest axis, -min(r).
inline double sd_ellipsoid(Vec3d p, double rx, double ry, double rz) {
  const double k0 = Vec3d{p.x / rx, p.y / ry, p.z / rz}.length();
  const double k1 = Vec3d{p.x / (rx * rx), p.y / (ry * ry), p.z / (rz * rz)}.length();
  if (k1 == 0) return -std::min(rx, std::min(ry, rz));
  return k0 * (k0 - 1) / k1;
}

// Shape `kind` with its parameters as written (sizes as full extents) at p in its own frame.
inline double shape_distance(NodeKind kind, const double* s, Vec3d p) {
  switch (kind) {
    case NodeKind::kSphere:
      return sd_sphere(p, s[0]);
    case NodeKind::kBox:
      return sd_box(p, s[0] / 2, s[1] / 2, s[2] / 2);
    case NodeKind::kRoundedBox:
      return sd_box(p, s[0] / 2 - s[3], s[1] / 2 - s[3], s[2] / 2 - s[3]) - s[3];
    case NodeKind::kCylinder:
      return sd_cylinder(p, s[0], s[1] / 2);
    case NodeKind::kCapsule:
      return sd_capsule(p, s[0], s[1] / 2);
    case NodeKind::kTorus:
      return sd_torus(p, s[0], s[1]);
    case NodeKind::kCone:
      return sd_cone(p, s[0], s[1] / 2);
    case NodeKind::kPlane:
      return sd_plane(p, s[0], s[1], s[2], s[3]);
    case NodeKind::kEllipsoid:
      return sd_ellipsoid(p, s[0], s[1], s[2]);
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

// The polynomial smooth minimum and maximum (docs/csg.md): within k of each other the two values
// blend, lowering the minimum by at most k/4.
inline double smooth_min(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k / 4;
}
inline double smooth_max(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::max(a, b) + h * h * k / 4;
}

// A 3x4 affine map, row major: p' = m * p + t.
struct Affine {
  std::array<double, 9> m{1, 0, 0, 0, 1, 0, 0, 0, 1};
  Vec3d t;
  Vec3d apply(Vec3d p) const {
    return {m[0] * p.x + m[1] * p.y + m[2] * p.z + t.x, m[3] * p.x + m[4] * p.y + m[5] * p.z + t.y,
            m[6] * p.x + m[7] * p.y + m[8] * p.z + t.z};
  }
  // this ∘ other: first other, then this.
  Affine after(const Affine& o) const {
    Affine r;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        r.m[i * 3 + j] = m[i * 3] * o.m[j] + m[i * 3 + 1] * o.m[3 + j] + m[i * 3 + 2] * o.m[6 + j];
    r.t = apply(o.t);
    return r;
  }
};

// The rotation by `degrees` about the unit axis (right-handed; Rodrigues' formula).
inline std::array<double, 9> rotation_matrix(double degrees, Vec3d axis) {
  const double a = degrees * (3.14159265358979323846 / 180.0);
  const double c = std::cos(a), s = std::sin(a), u = 1 - c;
  const double x = axis.x, y = axis.y, z = axis.z;
  return {c + x * x * u,     x * y * u - z * s, x * z * u + y * s,  //
          y * x * u + z * s, c + y * y * u,     y * z * u - x * s,  //
          z * x * u - y * s, z * y * u + x * s, c + z * z * u};
}

// Closed intervals of doubles, for the sound bounds clipping needs.
struct Interval {
  double lo = 0, hi = 0;
};
inline Interval operator+(Interval a, Interval b) {
  return {a.lo + b.lo, a.hi + b.hi};
}
inline Interval operator-(Interval a, double s) {
  return {a.lo - s, a.hi - s};
}
inline Interval scaled(Interval a, double s) {  // s >= 0
  return {a.lo * s, a.hi * s};
}
inline Interval square(Interval a) {
  if (a.lo >= 0) return {a.lo * a.lo, a.hi * a.hi};
  if (a.hi <= 0) return {a.hi * a.hi, a.lo * a.lo};
  return {0, std::max(a.lo * a.lo, a.hi * a.hi)};
}
inline Interval abs_interval(Interval a) {
  if (a.lo >= 0) return a;
  if (a.hi <= 0) return {-a.hi, -a.lo};
  return {0, std::max(-a.lo, a.hi)};
}
inline Interval sqrt_interval(Interval a) {
  return {std::sqrt(std::max(a.lo, 0.0)), std::sqrt(std::max(a.hi, 0.0))};
}

}  // namespace voxfield::csg::detail
