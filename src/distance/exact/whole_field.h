// voxfield — the whole-field exact transform's entry for its callers in the distance module
// (internal): compute_distance_field over the plan's domain, and slabs of a larger domain
// (slab_field.cpp), whose z sweeps start from the columns' sites beyond the slab.
#pragma once

#include "chunk_rows.h"
#include "voxfield/distance_slab.h"
#include "z_pass.h"

namespace voxfield::detail::exact {

// The exact field over p.domain. `beyond` (may be null) gives each column's sites outside the
// domain's z range; `solver_extent` is the extent of the whole problem, which picks the slice
// solvers' arithmetic (32-bit squared distances when its diagonal allows).
DistanceField compute_exact_field(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o,
                                  const Plan& p, const ColumnsBeyond* beyond, Vec3i solver_extent);

// Checks a slab's neighbours against the whole `domain` and the slab [z0, z1) (distance_slab.h's
// rules, InvalidArgument otherwise) and returns the slab's box. Both backends' slab fields use it.
Box3i check_slab_neighbours(const Box3i& domain, std::int32_t z0, std::int32_t z1,
                            const SlabNeighbours& neighbours);

}  // namespace voxfield::detail::exact
