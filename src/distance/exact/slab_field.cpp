// voxfield — exact fields of one z-slab of a larger domain (distance_slab.h): the columns' extreme
// sites of a slab, and the slab's field from its own voxels and its neighbours' extremes.
//
// Meijster, Roerdink & Hesselink, "A general algorithm for computing distance transforms in linear
// time" (2000): phase 1 (here along z) depends on the rest of a column only through the nearest
// site on either side, and the later phases stay within a z-slice. So the whole-field transform
// (whole_field.cpp) runs on the slab with its z sweeps started from those nearest sites, and gives
// the whole-domain field's values over the slab.
#include <algorithm>
#include <string>

#include "../field_plan.h"
#include "voxfield/distance_slab.h"
#include "voxfield/parallel.h"
#include "whole_field.h"

namespace voxfield {
namespace {

using detail::exact::SolidRows;

Box3i slab_of(const Box3i& domain, std::int32_t z0, std::int32_t z1) {
  return {{domain.begin.x, domain.begin.y, z0}, {domain.end.x, domain.end.y, z1}};
}

// The smallest box of whole chunks holding `b` (b not empty).
Box3i chunk_cover(const Box3i& b, int shift) {
  const int e = 1 << shift;
  auto lo = [&](int v) { return (v >> shift) * e; };
  auto hi = [&](int v) { return ((v - 1) >> shift) * e + e; };
  return {{lo(b.begin.x), lo(b.begin.y), lo(b.begin.z)}, {hi(b.end.x), hi(b.end.y), hi(b.end.z)}};
}

}  // namespace

ColumnSites slab_column_sites(const Grid<std::uint8_t>& occupancy, const Box3i& domain,
                              std::int32_t z0, std::int32_t z1) {
  const Box3i slab = slab_of(domain, z0, z1);
  if (domain.empty() || z0 >= z1 || !domain.contains(slab))
    throw InvalidArgument("slab z " + std::to_string(z0) + ".." + std::to_string(z1) +
                          " is not a non-empty part of the domain " + to_string(domain));
  const int X = domain.size().x, Y = domain.size().y;
  const std::size_t columns = static_cast<std::size_t>(X) * static_cast<std::size_t>(Y);
  ColumnSites out;
  out.lowest_solid.assign(columns, ColumnSites::kNoneLow);
  out.lowest_air.assign(columns, ColumnSites::kNoneLow);
  out.highest_solid.assign(columns, ColumnSites::kNoneHigh);
  out.highest_air.assign(columns, ColumnSites::kNoneHigh);
  const int shift = occupancy.chunk_shift(), edge = occupancy.chunk_edge();
  const Box3i cover = chunk_cover(slab, shift);
  const SolidRows world(occupancy, cover);
  parallel_for(static_cast<std::size_t>(Y), 1, [&](std::size_t yb, std::size_t ye) {
    for (std::size_t yi = yb; yi < ye; ++yi) {
      const int y = domain.begin.y + static_cast<int>(yi);
      const std::size_t row = yi * static_cast<std::size_t>(X);
      std::int32_t* __restrict ls = out.lowest_solid.data() + row;
      std::int32_t* __restrict hs = out.highest_solid.data() + row;
      std::int32_t* __restrict la = out.lowest_air.data() + row;
      std::int32_t* __restrict ha = out.highest_air.data() + row;
      for (int z = z0; z < z1; ++z) {
        for (int cx = 0; cx < (cover.size().x >> shift); ++cx) {
          const int c0 = cover.begin.x + cx * edge;
          const int x0 = std::max(domain.begin.x, c0), x1 = std::min(domain.end.x, c0 + edge);
          const std::uint8_t* __restrict w = world.row(cx, y, z) + (x0 - c0);
          const int o = x0 - domain.begin.x;
          // z only grows: the first voxel of a kind is its lowest, the last its highest.
          for (int i = 0; i < x1 - x0; ++i) {
            const bool solid = w[i] != 0;
            ls[o + i] = std::min(ls[o + i], solid ? z : ColumnSites::kNoneLow);
            hs[o + i] = std::max(hs[o + i], solid ? z : ColumnSites::kNoneHigh);
            la[o + i] = std::min(la[o + i], solid ? ColumnSites::kNoneLow : z);
            ha[o + i] = std::max(ha[o + i], solid ? ColumnSites::kNoneHigh : z);
          }
        }
      }
    }
  });
  return out;
}

namespace detail::exact {

Box3i check_slab_neighbours(const Box3i& domain, std::int32_t z0, std::int32_t z1,
                            const SlabNeighbours& neighbours) {
  const std::size_t columns =
      static_cast<std::size_t>(domain.size().x) * static_cast<std::size_t>(domain.size().y);
  for (const auto* a : {&neighbours.solid_below, &neighbours.air_below, &neighbours.solid_above,
                        &neighbours.air_above}) {
    if (a->size() != columns)
      throw InvalidArgument("slab neighbours: " + std::to_string(a->size()) +
                            " columns given, the domain has " + std::to_string(columns));
  }
  // A neighbour must lie in the domain on its side of the slab: anything else would be a distance
  // of the wrong sign.
  auto check = [&](const std::vector<std::int32_t>& a, bool below, const char* what) {
    for (const std::int32_t z : a) {
      const bool ok = below ? (z == ColumnSites::kNoneHigh || (z >= domain.begin.z && z < z0))
                            : (z == ColumnSites::kNoneLow || (z >= z1 && z < domain.end.z));
      if (!ok)
        throw InvalidArgument(std::string("slab neighbours: ") + what + " at z " +
                              std::to_string(z) + " is not " + (below ? "below" : "above") +
                              " the slab z " + std::to_string(z0) + ".." + std::to_string(z1) +
                              " within the domain " + to_string(domain));
    }
  };
  check(neighbours.solid_below, true, "a solid voxel");
  check(neighbours.air_below, true, "an air voxel");
  check(neighbours.solid_above, false, "a solid voxel");
  check(neighbours.air_above, false, "an air voxel");
  return slab_of(domain, z0, z1);
}

}  // namespace detail::exact

DistanceField compute_slab_distance_field(const Grid<std::uint8_t>& occupancy,
                                          const DistanceOptions& options, std::int32_t z0,
                                          std::int32_t z1, const SlabNeighbours& neighbours) {
  if (!options.domain || options.domain->empty())
    throw InvalidArgument("a slab's field needs the whole field's domain (options.domain)");
  const Box3i domain = *options.domain;
  const Box3i slab = slab_of(domain, z0, z1);
  // The plan first: it refuses a slab outside the domain before the neighbours are read.
  const detail::FieldPlan plan = detail::make_field_plan(occupancy, options, &slab);
  detail::exact::check_slab_neighbours(domain, z0, z1, neighbours);
  const detail::exact::ColumnsBeyond beyond{
      neighbours.solid_below.data(), neighbours.air_below.data(), neighbours.solid_above.data(),
      neighbours.air_above.data()};
  return detail::exact::compute_exact_field(occupancy, options, plan, &beyond, domain.size());
}

double effective_clamp(const DistanceOptions& options) {
  DistanceOptions o = options;
  o.domain = Box3i{{0, 0, 0}, {1, 1, 1}};  // the clamp does not depend on the domain
  o.nearest_sites = false;
  return detail::make_field_plan(Grid<std::uint8_t>(), o).clamp;
}

}  // namespace voxfield
