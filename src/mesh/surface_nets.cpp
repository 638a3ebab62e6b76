// voxfield — surface nets' vertex placement.
//
// S. F. F. Gibson, "Constrained Elastic Surface Nets: Generating Smooth Surfaces from Binary
// Segmented Data", MICCAI 1998, in its naive form (no relaxation): the vertex of a cell the
// surface crosses is the mean of the crossings on its edges (linear interpolation of the samples).
// The quads around it come from the dual grid (dual_grid.cpp).
#include <array>
#include <bit>
#include <cstdint>

#include "chunked_mesh.h"
#include "cube_cases.h"

namespace voxfield::detail::mesh {

std::array<double, 3> surface_nets_vertex(const Block&, const Lattice& lattice, Vec3i cell,
                                          const double* v) {
  unsigned mask = 0;
  for (unsigned c = 0; c < 8; ++c) mask |= static_cast<unsigned>(v[c] < 0) << c;
  const auto& edges = cube_edges();
  return crossing_mean(CubeCases::get(), mask, [&](unsigned e) {
    const CubeEdge& edge = edges[e];
    const double s0 = v[edge.from], s1 = v[edge.to];
    // Lattice::crossing's interpolation, inline unless there is a function to solve on.
    if (!lattice.value) return s0 / (s0 - s1);
    Vec3i p0 = cell;
    for (int a = 0; a < 3; ++a) p0[a] += edge.from >> a & 1;
    return lattice.crossing(p0, edge.axis, s0, s1);
  });
}

}  // namespace voxfield::detail::mesh
