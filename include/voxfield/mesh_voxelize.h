// voxfield — triangle meshes into voxels: the generalized winding number, solid voxelisation and
// signed distance fields.
//
// Meshes from scans and from modelling tools are rarely watertight: holes, overlapping pieces,
// flipped patches. The generalized winding number (Jacobson, Kavan & Sorkine-Hornung 2013) is the
// sum of the solid angles the triangles subtend, over 4π: 1 inside a closed surface, 0 outside,
// and a smooth, sensible value where the surface has holes — so "solid where it is >= 1/2" fills a
// holed mesh the way a person would. It is evaluated with the hierarchical approximation of
// Barill, Dickson, Schmidt, Levin & Jacobson 2018 ("Fast winding numbers for soups and clouds"):
// far clusters of triangles contribute through their dipole, near ones exactly.
//
// The voxel lattice is anchored at the origin: voxel (i, j, k) covers [i, i + 1) x [j, j + 1) x
// [k, k + 1) times the voxel size in the mesh's units, and is sampled at its centre. So a mesh at
// any position lands on the same voxels whatever else is in the file, and a world voxelised from a
// mesh lines up with the distance field of the same mesh.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/world.h"

namespace voxfield {

class Interrupter;

// Triangles over shared positions, in the file's units. Orientation matters for the sign (counter-
// clockwise seen from outside, as every format here expects); nothing else is assumed: holes,
// duplicate and degenerate triangles and non-manifold edges are all taken as they come.
struct TriangleMesh {
  std::vector<std::array<double, 3>> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;

  // Throws InvalidArgument for an index out of range or a non-finite position.
  void validate() const;
  // The positions' bounding box (min, max); both zero for an empty mesh.
  std::array<std::array<double, 3>, 2> bounds() const;
};

// The generalized winding number of a mesh at any point. Building sorts the triangles into a
// bounding-volume hierarchy (O(n log n)); each query then costs O(log n) for points away from the
// surface. Immutable after construction: queries may run from many threads at once.
class WindingNumber {
 public:
  // accuracy: Barill et al.'s beta — a cluster is approximated by its far-field expansion when the
  // query point is more than accuracy times the cluster's radius from its centre (2, as in the
  // paper; larger is more exact and slower). Throws InvalidArgument for accuracy < 1 or an
  // invalid mesh.
  explicit WindingNumber(const TriangleMesh& mesh, double accuracy = 2.0);
  ~WindingNumber();
  WindingNumber(WindingNumber&&) noexcept;
  WindingNumber& operator=(WindingNumber&&) noexcept;

  double operator()(const std::array<double, 3>& point) const;  // the hierarchical value
  // Whether the winding number at `point` is >= 1/2: the hierarchical value, asked again with four
  // times the accuracy when it lies within 1/4 of the threshold (near the holes of an open mesh;
  // never for a closed one, whose value is 0 or 1 away from the surface).
  bool inside(const std::array<double, 3>& point) const;
  // The exact sum over every triangle (Van Oosterom & Strackee's solid angle): O(n) per query.
  double exact(const std::array<double, 3>& point) const;

 private:
  struct Tree;
  double evaluate(const std::array<double, 3>& point, double accuracy) const;
  Tree* tree_ = nullptr;  // the triangles' corners in tree order, and the clusters
};

struct MeshVoxelOptions {
  double voxel_size = 1;  // edge of a voxel in the mesh's units, > 0
  // Voxels of air added around the mesh's bounds on every side (the distance field's margin).
  int padding_voxels = 2;
  std::uint8_t material = 1;  // of the solid voxels (voxelize_mesh), 1..255
  double accuracy = 2.0;      // WindingNumber's
  // Progress and cancellation (interrupt.h), asked between slices of voxels.
  Interrupter* interrupter = nullptr;
  std::uint64_t memory_limit_bytes = 0;  // 0: the process default (limits.h)
};

// The voxels whose centres lie within the mesh's bounds grown by options.padding_voxels: the box
// every function below works on (one voxel thick at least along each axis). Throws
// InvalidArgument for an empty mesh, a voxel size <= 0 or not finite, a box beyond 2^20 voxels
// along an axis or of 2^32 voxels or more.
Box3i mesh_voxel_box(const TriangleMesh& mesh, const MeshVoxelOptions& options);

// A world with `material` where the winding number at the voxel's centre is >= 1/2, bounded by
// mesh_voxel_box, in the frame of the mesh's units (voxel size options.voxel_size, origin 0): its
// meshes and .vdb files come out where the mesh was. Throws InvalidArgument (options, the mesh),
// ResourceLimitError (the box against the memory limit), Cancelled.
World voxelize_mesh(const TriangleMesh& mesh, const MeshVoxelOptions& options);

struct MeshDistanceOptions : MeshVoxelOptions {
  // Voxels within this many voxel edges of the surface get their exact distance to the nearest
  // triangle. Beyond the band each voxel takes its exact distance to the triangle nearest the
  // closest surface voxel (found by voxfield's exact transform): never below the true distance
  // and, as measured in docs/mesh_input.md, within a few hundredths of a voxel of it.
  double band_voxels = 3;
  bool signed_distance = true;  // negative where the winding number is >= 1/2
  // Clamp, in the mesh's units (0: none): distances beyond it read it (-it inside). A clamp within
  // the band is a narrow band, as OpenVDB's level sets are: nothing beyond it is computed but the
  // sign.
  double max_distance = 0;
};

// A signed distance field sampled at voxel centres, in the mesh's units.
struct MeshDistanceField {
  Box3i box;                     // the voxels (mesh_voxel_box)
  double voxel_size = 1;         // sample (i, j, k) sits at ((i, j, k) + 0.5) * voxel_size
  std::vector<float> values;     // x fastest, box.size() of them
  std::int64_t band_voxels = 0;  // how many were computed exactly in the narrow band

  float at(Vec3i p) const;  // p inside box
};

// Throws as voxelize_mesh, and InvalidArgument for band_voxels < 1.
MeshDistanceField mesh_distance_field(const TriangleMesh& mesh, const MeshDistanceOptions& options);

// The exact distance from a point to a triangle (Ericson, Real-Time Collision Detection, 5.1.5).
double point_triangle_distance(const std::array<double, 3>& p, const std::array<double, 3>& a,
                               const std::array<double, 3>& b, const std::array<double, 3>& c);

}  // namespace voxfield
