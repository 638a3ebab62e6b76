// voxfield — which boxes an incremental field update recomputes (internal; shared by the CPU's
// DynamicDistanceField and the GPU's gpu::DynamicField so both recompute exactly the same).
#pragma once

#include <vector>

#include "../field_plan.h"
#include "voxfield/edit.h"

namespace voxfield::detail {

struct UpdateRegion {
  Box3i out;  // values recomputed: a change's box grown by the reach, clipped to the domain
  Box3i in;   // sites they depend on: `out` grown by the reach again, clipped
};

// How far, in voxels along each axis, a change can move values: the clamp over the spacing, or
// the domain's extent when unclamped.
Vec3i field_reach(const FieldPlan& plan);

// The regions to recompute after the changes in `dirty`: their reach boxes, merged until none
// overlap (so no voxel is computed twice), each with the box of sites it needs.
std::vector<UpdateRegion> update_regions(const DirtyRegions& dirty, const Box3i& domain, Vec3i reach);

// A box inside the region `r` holding every voxel of an unsigned field whose value changes in the
// box `changed` can move (`field` holding the values before them), found by growing `changed` a
// shell at a time and reading only the voxels around it; `r` itself once the box exceeds
// `max_volume` voxels.
template <class T>
Box3i grow_affected(const FieldPlan& plan, const Grid<T>& field, const Box3i& r, const Box3i& changed, std::int64_t max_volume);

}  // namespace voxfield::detail
