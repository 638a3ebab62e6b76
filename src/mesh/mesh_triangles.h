// voxfield — small geometry shared by the mesh voxeliser and the mesh distance field (internal).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/interrupt.h"
#include "voxfield/mesh_voxelize.h"

namespace voxfield::detail {
namespace triangles {

using V3 = std::array<double, 3>;
inline V3 sub(const V3& a, const V3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline double dot(const V3& a, const V3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
// Distance from p to the segment ab (a point when a == b).
inline double segment_distance(const V3& p, const V3& a, const V3& b) {
  const V3 ab = sub(b, a), ap = sub(p, a);
  const double len2 = dot(ab, ab);
  const double t = len2 > 0 ? std::clamp(dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
  const V3 d{ap[0] - t * ab[0], ap[1] - t * ab[1], ap[2] - t * ab[2]};
  return std::sqrt(dot(d, d));
}

// The local x range [*x0, *x1] (clipped to [lo, hi]) of the row of voxel centres at (y, z) — in
// the mesh's units — whose distance to the plane of triangle abc is at most `reach`: a large
// triangle's voxels are then those near it, not its whole bounding box. A degenerate triangle
// (no plane) or one edge-on to x keeps [lo, hi]. Returns false when the range is empty.
inline bool row_near_plane(const V3& a, const V3& b, const V3& c, double y, double z, double reach,
                           double voxel, int box_begin_x, int lo, int hi, int* x0, int* x1) {
  const V3 n = cross(sub(b, a), sub(c, a));
  const double len = std::sqrt(dot(n, n));
  *x0 = lo;
  *x1 = hi;
  if (!(len > 0) || !(std::abs(n[0]) > 1e-9 * len)) return lo <= hi;
  // n . (p - a) = 0 at the plane: solve for p.x along the row, then widen by reach.
  const double at = (dot(n, a) - n[1] * y - n[2] * z) / n[0];
  const double half = reach * len / std::abs(n[0]);
  const double first = std::ceil((at - half) / voxel - 0.5) - box_begin_x;
  const double last = std::floor((at + half) / voxel - 0.5) - box_begin_x;
  if (first > *x0) *x0 = first > hi ? hi + 1 : static_cast<int>(first);
  if (last < *x1) *x1 = last < lo ? lo - 1 : static_cast<int>(last);
  return *x0 <= *x1;
}

}  // namespace triangles

// The centres of a box of voxels in the mesh's units. Local indices: 0 at box.begin.
struct VoxelCentres {
  Box3i box;
  double voxel_size;

  double coordinate(int axis, int local) const {
    return (static_cast<double>(box.begin[axis]) + local + 0.5) * voxel_size;
  }
  std::array<double, 3> at(int x, int y, int z) const {
    return {coordinate(0, x), coordinate(1, y), coordinate(2, z)};
  }
};

// Which voxels of `box` have a winding number >= 1/2 (1 per voxel, x fastest). `near_surface`
// marks voxels whose cells the surface may enter (at least every one it does); the rest are
// decided by regions (mesh_sign.cpp). Advances `progress` once per z slice.
std::vector<std::uint8_t> inside_voxels(const WindingNumber& winding, const Box3i& box,
                                        double voxel_size,
                                        const std::vector<std::uint8_t>& near_surface,
                                        Progress& progress);

}  // namespace voxfield::detail
