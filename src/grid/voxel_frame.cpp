// voxfield — the voxel-to-world frame (voxel_frame.h): the affine map, its inverse and checks.
#include "voxfield/voxel_frame.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "voxfield/error.h"

namespace voxfield {
namespace {

// Orthonormality is checked to this: a rotation read from a file in doubles (or built from
// degrees) is orthonormal to ~1e-15; 1e-9 leaves room for one written in floats' worth of digits
// being refused, which is the point — such a matrix would skew the world by 1e-7.
constexpr double kRotationTolerance = 1e-9;
// How far from orthonormal a rotation read from a file may be and still be taken as one: floats'
// precision, with room.
constexpr double kFloatRotationTolerance = 1e-5;

bool finite(Vec3d v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Vec3d column(const std::array<Vec3d, 3>& r, int c) {
  return {r[0][c], r[1][c], r[2][c]};
}

Vec3d times(const std::array<Vec3d, 3>& r, Vec3d v) {
  return {dot(r[0], v), dot(r[1], v), dot(r[2], v)};
}

// Rᵀ v: the rows of Rᵀ are R's columns.
Vec3d times_transposed(const std::array<Vec3d, 3>& r, Vec3d v) {
  return {dot(column(r, 0), v), dot(column(r, 1), v), dot(column(r, 2), v)};
}

double determinant(const std::array<Vec3d, 3>& r) {
  return dot(r[0], cross(r[1], r[2]));
}

std::string number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

std::string vec(Vec3d v) {
  return "(" + number(v.x) + ", " + number(v.y) + ", " + number(v.z) + ")";
}

}  // namespace

bool VoxelFrame::axis_aligned() const {
  return rotation == VoxelFrame{}.rotation;
}

Vec3d VoxelFrame::world_direction(Vec3d d_vox) const {
  return times(rotation, {d_vox.x * voxel_size_world.x, d_vox.y * voxel_size_world.y,
                          d_vox.z * voxel_size_world.z});
}

Vec3d VoxelFrame::world_from_vox(Vec3d p_vox) const {
  return origin_world + world_direction(p_vox);
}

Vec3d VoxelFrame::vox_direction(Vec3d d_world) const {
  const Vec3d local = times_transposed(rotation, d_world);
  return {local.x / voxel_size_world.x, local.y / voxel_size_world.y, local.z / voxel_size_world.z};
}

Vec3d VoxelFrame::vox_from_world(Vec3d p_world) const {
  return vox_direction(p_world - origin_world);
}

Vec3d VoxelFrame::world_normal(Vec3d n_vox) const {
  const Vec3d n = times(rotation, {n_vox.x / voxel_size_world.x, n_vox.y / voxel_size_world.y,
                                   n_vox.z / voxel_size_world.z});
  const double length = n.length();
  return length > 0 ? n * (1 / length) : n;
}

std::array<double, 12> VoxelFrame::world_from_vox_matrix() const {
  std::array<double, 12> m{};
  for (int row = 0; row < 3; ++row) {
    for (int c = 0; c < 3; ++c) m[4 * row + c] = rotation[row][c] * voxel_size_world[c];
    m[4 * row + 3] = origin_world[row];
  }
  return m;
}

void VoxelFrame::validate(const std::string& what) const {
  if (!finite(origin_world)) throw InvalidArgument(what + ": the origin is not finite");
  for (int a = 0; a < 3; ++a) {
    if (!(std::isfinite(voxel_size_world[a]) && voxel_size_world[a] > 0))
      throw InvalidArgument(what + ": the voxel size " + vec(voxel_size_world) +
                            " is not finite and positive");
  }
  for (int a = 0; a < 3; ++a) {
    if (!finite(rotation[a])) throw InvalidArgument(what + ": the rotation is not finite");
    for (int b = 0; b < 3; ++b) {
      const double want = a == b ? 1 : 0;
      if (std::abs(dot(rotation[a], rotation[b]) - want) > kRotationTolerance)
        throw InvalidArgument(what + ": the rotation's rows are not orthonormal");
    }
  }
  if (determinant(rotation) < 0)
    throw InvalidArgument(what + ": the rotation is a mirror (determinant -1)");
}

VoxelFrame VoxelFrame::from_matrix(const std::array<double, 12>& m, const std::string& what) {
  VoxelFrame f;
  for (int c = 0; c < 3; ++c) {
    const Vec3d axis{m[c], m[4 + c], m[8 + c]};
    const double length = axis.length();
    if (!(length > 0) || !std::isfinite(length))
      throw InvalidArgument(what + ": a transform with a zero or non-finite voxel size");
    f.voxel_size_world[c] = length;
    for (int row = 0; row < 3; ++row) f.rotation[row][c] = axis[row] / length;
  }
  f.origin_world = {m[3], m[7], m[11]};
  // A rotation stored in floats (most tools' transforms) is orthonormal to ~1e-7, not to
  // validate's 1e-9: within kFloatRotationTolerance it is made exactly orthonormal (Gram-Schmidt
  // on the columns), a change far below the file's own precision. A shear or mirror is not.
  double worst = 0;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) {
      const Vec3d ca = column(f.rotation, a), cb = column(f.rotation, b);
      worst = std::max(worst, std::abs(dot(ca, cb) - (a == b ? 1.0 : 0.0)));
    }
  if (worst > kRotationTolerance && worst < kFloatRotationTolerance &&
      determinant(f.rotation) > 0) {
    const Vec3d c0 = column(f.rotation, 0), c1 = column(f.rotation, 1);
    const Vec3d u0 = c0.normalized();
    const Vec3d u1 = (c1 - u0 * dot(u0, c1)).normalized();
    const Vec3d u2 = cross(u0, u1);
    for (int row = 0; row < 3; ++row) f.rotation[row] = {u0[row], u1[row], u2[row]};
  }
  try {
    f.validate(what);
  } catch (const InvalidArgument&) {
    throw InvalidArgument(what +
                          ": the transform is not a rotation and a positive scale per axis (it "
                          "shears or mirrors), which a voxel frame cannot hold");
  }
  return f;
}

std::array<Vec3d, 3> rotation_about(double angle_deg, Vec3d axis) {
  if (!finite(axis) || axis.length() == 0 || !std::isfinite(angle_deg))
    throw InvalidArgument(
        "rotation: the axis must be a finite non-zero vector and the angle finite");
  const Vec3d u = axis.normalized();
  const double a = angle_deg * 3.14159265358979323846 / 180.0, c = std::cos(a), s = std::sin(a),
               t = 1 - c;
  return {{{t * u.x * u.x + c, t * u.x * u.y - s * u.z, t * u.x * u.z + s * u.y},
           {t * u.x * u.y + s * u.z, t * u.y * u.y + c, t * u.y * u.z - s * u.x},
           {t * u.x * u.z - s * u.y, t * u.y * u.z + s * u.x, t * u.z * u.z + c}}};
}

std::string describe(const VoxelFrame& frame) {
  std::string s =
      "origin " + vec(frame.origin_world) + ", voxel size " + vec(frame.voxel_size_world);
  if (!frame.axis_aligned()) {
    s += ", rotation rows " + vec(frame.rotation[0]) + " " + vec(frame.rotation[1]) + " " +
         vec(frame.rotation[2]);
  }
  return s;
}

}  // namespace voxfield
