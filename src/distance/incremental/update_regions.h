// voxfield — which boxes an incremental field update recomputes (internal; shared by the CPU's
// DynamicDistanceField and the GPU's gpu::DynamicField so both recompute exactly the same), and
// the CPU's searches that shrink them (affected_voxels.cpp).
#pragma once

#include <array>
#include <limits>
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
std::vector<UpdateRegion> update_regions(const DirtyRegions& dirty, const Box3i& domain,
                                         Vec3i reach);

// `regions`, each whose box of sites holds more than `max_in_voxels` voxels cut, across the axis
// that needs the fewest, into slabs of its `out` box, each with the sites it needs (the slab
// grown by the reach, clipped to the domain) and at most `max_in_voxels` of them: the same values,
// computed in parts by a device whose buffers hold no more. A region no cut brings under the
// bound (an unclamped field's: its reach is the whole domain) stays whole, for the caller to cut
// otherwise (the GPU's z-slabs with column neighbours, src/distance/gpu/column_slabs.h).
std::vector<UpdateRegion> split_regions(const std::vector<UpdateRegion>& regions,
                                        const Box3i& domain, Vec3i reach,
                                        std::int64_t max_in_voxels);

// A box inside the region `r` holding every voxel of an unsigned field whose value changes in the
// box `changed` can move (`field` holding the values before them), found by growing `changed` a
// shell at a time and reading only the voxels around it; `r` itself once the box exceeds
// `max_volume` voxels.
template <class T>
Box3i grow_affected(const FieldPlan& plan, const Grid<T>& field, const Box3i& r,
                    const Box3i& changed, std::int64_t max_volume);

// `kind`: what the changes did — only removed solids (values can only rise, so voxels already at
// the clamp stay there), only added them (values can only fall, so voxels at 0 stay there), or
// both.
enum class Changes { kRemovals, kAdditions, kBoth };

// The bounding box of the voxels of `r` (`old` holding their values before the changes, x fastest)
// whose old distance reaches the box `changed`: only they can change; empty when none can.
template <class T>
Box3i affected_box(const FieldPlan& plan, const Box3i& r, const std::vector<T>& old,
                   const Box3i& changed, Changes kind);

// After removals, the new values inside the affected box `a` are bounded by the unchanged values
// around it: new(p) <= old(q) + |p - q| for every q outside `a` (distances are 1-Lipschitz, and q
// keeps its value). Using q straight across each face of `a` gives a bound M on every new value
// in `a`, so only sites within M of `a` matter — for a hole carved in solid ground, a few voxels
// instead of the clamp. Each face also bounds on its own how far beyond it a nearest site can lie:
// with F the largest old value on the face below `a` along axis k and p's nearest site s,
//     (p_k - s_k) * spacing_k <= |p - s| = new(p) <= F + (p_k - a.begin_k + 1) * spacing_k,
// so s_k >= a.begin_k - 1 - F / spacing_k whatever p is (every metric bounds each axis's step by
// the distance) — after a carve at the ground's surface, the face in the ground (F near 0) lets
// the sites below it be skipped, where M reaches the clamp through the face in the open air.
// Faces on the edge of the region `r` (beyond it another region may change values) or of the
// domain give no bound: +inf.
struct NewValueBounds {
  double all = std::numeric_limits<double>::infinity();  // M: every new value in `a`
  // The largest old value on the face just below / above `a` along each axis.
  std::array<double, 3> lo_face{all, all, all}, hi_face{all, all, all};
};

// The bounds above for the box `a` inside the region `r`, from the old values of `field` around it.
template <class T>
NewValueBounds new_value_bound(const FieldPlan& plan, const Grid<T>& field, const Box3i& r,
                               const Box3i& a);

// A box holding every solid voxel of `box` (empty if it holds none), from the chunks alone.
Box3i solid_bounds(const Grid<std::uint8_t>& occupancy, const Box3i& box);

}  // namespace voxfield::detail
