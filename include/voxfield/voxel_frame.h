// voxfield — where a world's voxels sit in the world: the frame that maps voxel coordinates to
// world coordinates (docs/frames.md).
//
// Voxel coordinates ("_vox"): voxel (i, j, k) spans [i, i+1) x [j, j+1) x [k, k+1), so its centre
// is (i + 1/2, j + 1/2, k + 1/2) — the convention of every voxfield mesh, ray and render. World
// coordinates ("_world") are a scan's millimetres, a game's metres, a CAD model's units:
//
//   p_world = origin_world + R * (voxel_size_world ⊙ p_vox)
//
// with R a rotation (rows, det +1) and ⊙ the per-axis product. The identity frame (origin 0, unit
// voxels, no rotation) is every world's until it is given one, and makes world coordinates voxel
// coordinates. A frame places results; it does not change what a field measures: distances stay
// in voxel edges times the field's spacing (distance.h).
#pragma once

#include <array>
#include <string>

#include "voxfield/box.h"

namespace voxfield {

struct VoxelFrame {
  Vec3d origin_world{0, 0, 0};  // where voxel coordinate (0, 0, 0) — a voxel's corner — lies
  Vec3d voxel_size_world{1, 1, 1};  // a voxel's edge along each of its axes, world units, > 0
  // Rows of the rotation from the voxel axes to world axes.
  std::array<Vec3d, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};

  friend bool operator==(const VoxelFrame&, const VoxelFrame&) = default;

  bool is_identity() const { return *this == VoxelFrame{}; }
  // Whether the rotation is the identity (then a voxel's axes are the world's).
  bool axis_aligned() const;

  Vec3d world_from_vox(Vec3d p_vox) const;
  Vec3d vox_from_world(Vec3d p_world) const;
  // The world position of voxel v's centre.
  Vec3d voxel_centre_world(Vec3i v) const {
    return world_from_vox({v.x + 0.5, v.y + 0.5, v.z + 0.5});
  }
  // A direction's image (no translation): R * (voxel_size_world ⊙ d_vox).
  Vec3d world_direction(Vec3d d_vox) const;
  // Its inverse: a world direction in voxel coordinates, (R^T d_world) / voxel_size_world.
  Vec3d vox_direction(Vec3d d_world) const;
  // A surface normal given in voxel coordinates, carried into the world and normalised: the
  // inverse transpose, R * (n_vox / voxel_size_world), so that it stays perpendicular to the
  // surface under an anisotropic scale. A zero normal stays zero.
  Vec3d world_normal(Vec3d n_vox) const;

  // The 3 x 4 matrix of world_from_vox, rows: world = m * (p_vox, 1).
  std::array<double, 12> world_from_vox_matrix() const;

  // Throws InvalidArgument naming `what` and the cause: a non-finite origin, a voxel size that is
  // not finite and positive, a rotation that is not orthonormal with determinant +1 (within 1e-9).
  void validate(const std::string& what) const;

  // The frame of a 3 x 4 affine matrix m (rows, world = m * (p_vox, 1)): voxel sizes are the
  // columns' lengths and the rotation the normalised columns, made exactly orthonormal when they
  // are within 1e-5 of it (a rotation stored in floats). Throws InvalidArgument when the matrix
  // is not a rotation times a positive scale (a shear or a mirror), naming `what`.
  static VoxelFrame from_matrix(const std::array<double, 12>& m, const std::string& what);
};

// The rotation by `angle_deg` degrees about `axis` (normalised here), as rows (Rodrigues' formula).
// Throws InvalidArgument for a zero or non-finite axis or a non-finite angle.
std::array<Vec3d, 3> rotation_about(double angle_deg, Vec3d axis);

// "origin (x, y, z), voxel size (sx, sy, sz)[, rotated]" for reports.
std::string describe(const VoxelFrame& frame);

}  // namespace voxfield
