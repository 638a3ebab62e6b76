// voxfield — topology and measures of a triangle mesh: the edge census (each undirected edge with
// the triangles using it and their directions), the Euler characteristic, area and the enclosed
// volume by the divergence theorem (the sum of the signed tetrahedra from the origin).
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/mesh.h"

namespace voxfield {

MeshStats mesh_stats(const Mesh& mesh) {
  for (const std::uint32_t i : mesh.indices)
    if (i >= mesh.positions.size())
      throw InvalidArgument("mesh_stats: index " + std::to_string(i) + " is past the last vertex");
  MeshStats s;
  s.vertices = mesh.positions.size();
  s.triangles = mesh.triangle_count();
  // One record per directed triangle edge: the undirected edge (both 32-bit ends) and its
  // direction, so that sorting groups each edge's uses together.
  struct Use {
    std::uint64_t edge;
    bool forward;
    bool operator<(const Use& o) const {
      return edge < o.edge || (edge == o.edge && forward < o.forward);
    }
  };
  std::vector<Use> uses;
  uses.reserve(3 * s.triangles);
  for (std::size_t t = 0; t < s.triangles; ++t) {
    const std::uint32_t* v = mesh.indices.data() + 3 * t;
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) ++s.degenerate_triangles;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = v[k], b = v[(k + 1) % 3];
      const std::uint64_t lo = std::min(a, b), hi = std::max(a, b);
      uses.push_back({lo << 32 | hi, a < b});
    }
    const auto& p0 = mesh.positions[v[0]];
    const auto& p1 = mesh.positions[v[1]];
    const auto& p2 = mesh.positions[v[2]];
    const double ax = double{p1[0]} - p0[0], ay = double{p1[1]} - p0[1], az = double{p1[2]} - p0[2];
    const double bx = double{p2[0]} - p0[0], by = double{p2[1]} - p0[1], bz = double{p2[2]} - p0[2];
    const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    s.area_units2 += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
    // det(p0, p1, p2) / 6 = p0 . (p1 x p2) / 6, computed relative to p0 for accuracy: the same as
    // p0 . (a x b) / 6 with a, b the edges from p0.
    s.signed_volume_units3 += (double{p0[0]} * cx + double{p0[1]} * cy + double{p0[2]} * cz) / 6;
  }
  std::sort(uses.begin(), uses.end());
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    int forward = 0;
    while (j < uses.size() && uses[j].edge == uses[i].edge) forward += uses[j++].forward;
    const std::size_t count = j - i;
    ++s.edges;
    if (count == 1)
      ++s.boundary_edges;
    else if (count > 2)
      ++s.nonmanifold_edges;
    else if (forward != 1)
      ++s.misoriented_edges;
    i = j;
  }
  s.euler_characteristic = static_cast<std::int64_t>(s.vertices) -
                           static_cast<std::int64_t>(s.edges) +
                           static_cast<std::int64_t>(s.triangles);
  return s;
}

}  // namespace voxfield
