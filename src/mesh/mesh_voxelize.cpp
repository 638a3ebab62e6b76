// Triangle meshes into solid voxels: every voxel whose centre has a generalized winding number of
// at least 1/2 (Jacobson et al. 2013; winding_number.cpp) is solid — the definition that fills a
// mesh with holes the way its closed version would be filled.
//
// Away from the surface whole regions are decided from their boundaries (mesh_sign.cpp); the
// voxels near it are asked one by one.
#include <cmath>

#include "mesh_triangles.h"
#include "voxfield/error.h"
#include "voxfield/interrupt.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_voxelize.h"
#include "voxfield/parallel.h"

namespace voxfield {

void TriangleMesh::validate() const {
  for (std::size_t i = 0; i < positions.size(); ++i)
    for (double v : positions[i])
      if (!std::isfinite(v))
        throw InvalidArgument("mesh: position " + std::to_string(i) + " is not finite");
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (std::uint32_t v : triangles[t])
      if (v >= positions.size())
        throw InvalidArgument("mesh: triangle " + std::to_string(t) + " names vertex " +
                              std::to_string(v) + " of " + std::to_string(positions.size()));
}

std::array<std::array<double, 3>, 2> TriangleMesh::bounds() const {
  std::array<std::array<double, 3>, 2> b{{{0, 0, 0}, {0, 0, 0}}};
  bool first = true;
  for (const auto& tri : triangles)
    for (std::uint32_t v : tri)
      for (int k = 0; k < 3; ++k) {
        const double x = positions[v][k];
        if (first || x < b[0][k]) b[0][k] = x;
        if (first || x > b[1][k]) b[1][k] = x;
        if (k == 2) first = false;
      }
  return b;
}

Box3i mesh_voxel_box(const TriangleMesh& mesh, const MeshVoxelOptions& options) {
  const double v = options.voxel_size;
  if (!(v > 0) || !std::isfinite(v))
    throw InvalidArgument("mesh voxels: the voxel size must be positive and finite");
  if (options.padding_voxels < 0 || options.padding_voxels > 1024)
    throw InvalidArgument("mesh voxels: the padding must be 0..1024 voxels");
  if (options.material == 0) throw InvalidArgument("mesh voxels: the material must be 1..255");
  mesh.validate();
  if (mesh.triangles.empty()) throw InvalidArgument("mesh voxels: the mesh has no triangles");
  const auto b = mesh.bounds();
  Box3i box;
  for (int k = 0; k < 3; ++k) {
    // Voxel i's centre (i + 1/2) v lies in [lo - pad v, hi + pad v].
    const double first = std::ceil(b[0][k] / v - 0.5) - options.padding_voxels;
    const double last = std::floor(b[1][k] / v - 0.5) + options.padding_voxels;
    if (!(last - first < double{1 << 20}) || !(std::abs(first) < kCoordLimit / 2) ||
        !(std::abs(last) < kCoordLimit / 2))
      throw InvalidArgument("mesh voxels: a voxel size of " + std::to_string(v) +
                            " makes the mesh over 2^20 voxels along an axis or beyond voxfield's "
                            "coordinates; choose a larger voxel size");
    box.begin[k] = static_cast<std::int32_t>(first);
    // A mesh flat along an axis (and no padding) still gets one layer of voxels.
    box.end[k] = static_cast<std::int32_t>(std::max(last, first)) + 1;
  }
  // Voxels are indexed in 32 bits by the sign's regions and the far field's lists.
  if (box.volume() >= (std::int64_t{1} << 32))
    throw InvalidArgument("mesh voxels: a voxel size of " + std::to_string(v) + " makes " +
                          to_string(box.size()) +
                          " voxels, 2^32 or more; choose a larger voxel size");
  return box;
}

World voxelize_mesh(const TriangleMesh& mesh, const MeshVoxelOptions& options) {
  const Box3i box = mesh_voxel_box(mesh, options);
  // The mask, the regions and their queue (9 bytes a voxel), the boundary lists (up to 16), the
  // result and the world's copy (2); the winding number's tree, about 120 bytes a triangle.
  require_memory(add_sat(mul_sat(static_cast<std::uint64_t>(box.volume()), 27),
                         mul_sat(mesh.triangles.size(), 120)),
                 options.memory_limit_bytes, "voxelize_mesh",
                 "a box of " + to_string(box.size()) + " voxels");
  const WindingNumber winding(mesh, options.accuracy);
  const Vec3i size = box.size();
  // The cells the surface may enter, and their neighbours: centres within two voxels of each
  // triangle's plane and bounding box (a superset; mesh_sign.cpp wants its regions' cells more than
  // a voxel from the surface). Rows are clipped to the plane, so a large triangle costs its area.
  Progress progress(options.interrupter, "voxelising a mesh", size.z);
  std::vector<std::uint8_t> near_surface(static_cast<std::size_t>(box.volume()), 0);
  const double v = options.voxel_size;
  const double reach = 2 * v;
  const detail::VoxelCentres centres{box, v};
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    if (t % 4096 == 0 && !progress.keep_going()) progress.throw_if_cancelled();
    int lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      double a = HUGE_VAL, b = -HUGE_VAL;
      for (std::uint32_t p : tri) {
        a = std::min(a, mesh.positions[p][k]);
        b = std::max(b, mesh.positions[p][k]);
      }
      lo[k] = std::max(0, static_cast<int>(std::ceil((a - reach) / v - 0.5)) - box.begin[k]);
      hi[k] =
          std::min(size[k] - 1, static_cast<int>(std::floor((b + reach) / v - 0.5)) - box.begin[k]);
    }
    const auto &pa = mesh.positions[tri[0]], &pb = mesh.positions[tri[1]],
               &pc = mesh.positions[tri[2]];
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y) {
        int x0, x1;
        if (!detail::triangles::row_near_plane(pa, pb, pc, centres.coordinate(1, y),
                                               centres.coordinate(2, z), reach, v, box.begin.x,
                                               lo[0], hi[0], &x0, &x1))
          continue;
        std::fill_n(near_surface.data() + (static_cast<std::size_t>(z) * size.y + y) * size.x + x0,
                    x1 - x0 + 1, std::uint8_t{1});
      }
  }
  std::vector<std::uint8_t> dense = detail::inside_voxels(winding, box, v, near_surface, progress);
  progress.throw_if_cancelled();
  for (std::uint8_t& m : dense) m = m ? options.material : 0;
  World world(Grid<std::uint8_t>::kDefaultChunkEdge, box);
  // Voxel (i, j, k)'s centre at ((i, j, k) + 1/2) * voxel size in the mesh's units: the frame.
  world.frame.voxel_size_world = Vec3d{1, 1, 1} * v;
  world.voxels.copy_from_dense(box, dense.data());
  world.voxels.compact();
  return world;
}

// Ericson, Real-Time Collision Detection (2005), 5.1.5: the closest point is found by testing
// which Voronoi region of the triangle (three vertices, three edges, the face) holds the point,
// using only dot products. A degenerate triangle (collinear or coincident corners) has no face
// region: its distance is the smallest to its three edges as segments.
double point_triangle_distance(const std::array<double, 3>& p, const std::array<double, 3>& a,
                               const std::array<double, 3>& b, const std::array<double, 3>& c) {
  using detail::triangles::dot;
  using detail::triangles::sub;
  const auto ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
  const auto closest_distance = [&](const std::array<double, 3>& q) {
    const auto d = sub(p, q);
    return std::sqrt(dot(d, d));
  };
  const auto n = detail::triangles::cross(ab, ac);
  const double n2 = dot(n, n);
  const double scale = std::max({dot(ab, ab), dot(ac, ac), dot(sub(c, b), sub(c, b))});
  if (!(n2 > 1e-24 * scale * scale)) {
    return std::min({detail::triangles::segment_distance(p, a, b),
                     detail::triangles::segment_distance(p, b, c),
                     detail::triangles::segment_distance(p, c, a)});
  }
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return closest_distance(a);
  const auto bp = sub(p, b);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return closest_distance(b);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double t = d1 / (d1 - d3);
    return closest_distance({a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]});
  }
  const auto cp = sub(p, c);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return closest_distance(c);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double t = d2 / (d2 - d6);
    return closest_distance({a[0] + t * ac[0], a[1] + t * ac[1], a[2] + t * ac[2]});
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    const double t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return closest_distance(
        {b[0] + t * (c[0] - b[0]), b[1] + t * (c[1] - b[1]), b[2] + t * (c[2] - b[2])});
  }
  // The face: the distance to the triangle's plane.
  return std::abs(dot(ap, n)) / std::sqrt(n2);
}

}  // namespace voxfield
