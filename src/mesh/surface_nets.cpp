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
  // Three scalars, not an array indexed by axis: the array lived in memory and its read-back
  // stalled store forwarding.
  double mx = 0, my = 0, mz = 0;
  int crossings = 0;
  for (unsigned bits = CubeCases::get().crossed_edges(mask); bits != 0; bits &= bits - 1) {
    const CubeEdge& e = cube_edges()[static_cast<std::size_t>(std::countr_zero(bits))];
    const double s0 = v[e.from], s1 = v[e.to];
    // Lattice::crossing's interpolation, inline unless there is a function to solve on.
    double t;
    if (lattice.value) {
      Vec3i p0 = cell;
      for (int a = 0; a < 3; ++a) p0[a] += e.from >> a & 1;
      t = lattice.crossing(p0, e.axis, s0, s1);
    } else {
      t = s0 / (s0 - s1);
    }
    mx += e.axis == 0 ? t : (e.from & 1);
    my += e.axis == 1 ? t : (e.from >> 1 & 1);
    mz += e.axis == 2 ? t : (e.from >> 2 & 1);
    ++crossings;
  }
  // (The cell has a crossing: a quad reached it.)
  return {mx / crossings, my / crossings, mz / crossings};
}

}  // namespace voxfield::detail::mesh
