// voxfield — surface nets' vertex placement.
//
// S. F. F. Gibson, "Constrained Elastic Surface Nets: Generating Smooth Surfaces from Binary
// Segmented Data", MICCAI 1998, in its naive form (no relaxation): the vertex of a cell the
// surface crosses is the mean of the crossings on its edges (linear interpolation of the samples).
// The quads around it come from the dual grid (dual_grid.cpp).
#include "chunked_mesh.h"
#include "cube_cases.h"

namespace voxfield::detail::mesh {

std::array<double, 3> surface_nets_vertex(const Block&, const Lattice& lattice, Vec3i cell,
                                          const double* v) {
  std::array<double, 3> mean{0, 0, 0};
  int crossings = 0;
  for (const CubeEdge& e : cube_edges()) {
    const double s0 = v[e.from], s1 = v[e.to];
    if ((s0 < 0) == (s1 < 0)) continue;
    Vec3i p0 = cell;
    for (int a = 0; a < 3; ++a) p0[a] += e.from >> a & 1;
    const double t = lattice.crossing(p0, e.axis, s0, s1);
    for (int a = 0; a < 3; ++a)
      mean[static_cast<std::size_t>(a)] += a == e.axis ? t : (e.from >> a & 1);
    ++crossings;
  }
  for (double& m : mean) m /= crossings;  // the cell has a crossing: a quad reached it
  return mean;
}

}  // namespace voxfield::detail::mesh
