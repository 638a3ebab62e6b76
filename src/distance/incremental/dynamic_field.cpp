// voxfield — incremental exact distance updates by local recomputation (see dynamic_field.h):
// DynamicDistanceField, and the regions an update recomputes (update_regions.h, shared with the
// GPU). With clamp D an edit in box B changes values only in B grown by D, computed from the sites
// in B grown by 2D; update() takes each such region in four steps: shrink it to the voxels the
// edit can move (affected_voxels.cpp), find the box of sites their values can reach, recompute
// them with the exact kernel (exact/local_region.cpp), and write them back.
#include "voxfield/dynamic_field.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <variant>
#include <vector>

#include "update_regions.h"

namespace voxfield {
namespace detail {
namespace {

Box3i grow(const Box3i& b, Vec3i by) {
  return {b.begin - by, b.end + by};
}

// Merges boxes that overlap until none do, so that no voxel is recomputed twice.
std::vector<Box3i> merge_overlapping(std::vector<Box3i> boxes) {
  bool merged = true;
  while (merged) {
    merged = false;
    for (std::size_t i = 0; i < boxes.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < boxes.size(); ++j) {
        if (boxes[i].intersect(boxes[j]).empty()) continue;
        boxes[i] = boxes[i].unite(boxes[j]);
        boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(j));
        merged = true;
        break;
      }
  }
  return boxes;
}

}  // namespace

Vec3i field_reach(const FieldPlan& plan) {
  const Vec3i size = plan.domain.size();
  Vec3i reach;
  for (int k = 0; k < 3; ++k)
    reach[k] =
        std::isfinite(plan.clamp)
            ? static_cast<int>(std::min<double>(std::ceil(plan.clamp / plan.spacing[k]), size[k]))
            : size[k];
  return reach;
}

std::vector<UpdateRegion> update_regions(const DirtyRegions& dirty, const Box3i& domain,
                                         Vec3i reach) {
  std::vector<Box3i> reach_boxes;
  for (const Box3i& b : dirty.boxes()) {
    const Box3i r = grow(b, reach).intersect(domain);
    if (!r.empty()) reach_boxes.push_back(r);
  }
  std::vector<UpdateRegion> regions;
  for (const Box3i& r : merge_overlapping(std::move(reach_boxes)))
    regions.push_back({r, grow(r, reach).intersect(domain)});
  return regions;
}

std::vector<UpdateRegion> split_regions(const std::vector<UpdateRegion>& regions,
                                        const Box3i& domain, Vec3i reach,
                                        std::int64_t max_in_voxels) {
  std::vector<UpdateRegion> out;
  for (const UpdateRegion& r : regions) {
    if (r.in.volume() <= max_in_voxels) {
      out.push_back(r);
      continue;
    }
    // Along axis a, a slab of s voxels of `out` needs at most s + 2 * reach[a] of `in`'s (the
    // other two extents are in's own): the axis that needs the fewest slabs.
    int best_axis = -1;
    std::int64_t best_slabs = 0;
    for (int a = 0; a < 3; ++a) {
      const std::int64_t across = r.in.volume() / r.in.size()[a];
      const std::int64_t slab = max_in_voxels / across - 2 * static_cast<std::int64_t>(reach[a]);
      if (slab < 1) continue;
      const std::int64_t slabs = (r.out.size()[a] + slab - 1) / slab;
      if (best_axis < 0 || slabs < best_slabs) best_axis = a, best_slabs = slabs;
    }
    if (best_axis < 0) {
      out.push_back(r);
      continue;
    }
    // Slabs of equal thickness (to one voxel): none thinner than it must be.
    const int a = best_axis, length = r.out.size()[a];
    for (std::int64_t k = 0; k < best_slabs; ++k) {
      Box3i slab = r.out;
      slab.begin[a] = r.out.begin[a] + static_cast<int>(length * k / best_slabs);
      slab.end[a] = r.out.begin[a] + static_cast<int>(length * (k + 1) / best_slabs);
      out.push_back({slab, grow(slab, reach).intersect(domain)});
    }
  }
  return out;
}

namespace {

// ---- The steps of DynamicDistanceField::update, one region at a time ---------------------------

// What an update asks of every region it recomputes.
struct RegionUpdate {
  const FieldPlan& plan;
  const Grid<std::uint8_t>& occupancy;
  Box3i domain;
  Vec3i reach;
  Changes kind;
  // The changes only placed solids into air, in an unsigned field without nearest sites: the new
  // values are the minimum of the old ones and the distance to the new sites (see update()).
  bool additions_only;
};

// The changes whose reach touches the region `r`, as one box.
Box3i changes_near(const std::vector<Box3i>& changed, const Box3i& r, Vec3i reach) {
  Box3i near;
  for (const Box3i& b : changed)
    if (!Box3i{b.begin - reach, b.end + reach}.intersect(r).empty()) near = near.unite(b);
  return near;
}

// Whether every chunk of `r` is uniform at the clamp: open space far from everything.
template <class T>
bool all_at_clamp(const FieldPlan& plan, const Grid<T>& field, const Box3i& r) {
  const T clamp_stored = encode_distance<T>(plan.clamp, plan);
  const int shift = field.chunk_shift();
  for (int cz = r.begin.z >> shift; cz <= (r.end.z - 1) >> shift; ++cz)
    for (int cy = r.begin.y >> shift; cy <= (r.end.y - 1) >> shift; ++cy)
      for (int cx = r.begin.x >> shift; cx <= (r.end.x - 1) >> shift; ++cx) {
        const auto view = field.chunk_view({cx, cy, cz});
        if (!(view.uniform() && view.uniform_value == clamp_stored)) return false;
      }
  return true;
}

// Keeps of `old` (the values of the box `from`, x fastest) those of the box `to` inside it, moved
// to the front in place.
template <class T>
void keep_box(std::vector<T>& old, const Box3i& from, const Box3i& to) {
  const Vec3i fs = from.size(), ts = to.size();
  std::size_t k = 0;
  for (int z = to.begin.z; z < to.end.z; ++z)
    for (int y = to.begin.y; y < to.end.y; ++y) {
      const std::size_t at = (static_cast<std::size_t>(z - from.begin.z) * fs.y +
                              static_cast<std::size_t>(y - from.begin.y)) *
                                 fs.x +
                             static_cast<std::size_t>(to.begin.x - from.begin.x);
      if (at != k)  // at > k: rows only move towards the front
        std::copy(old.begin() + static_cast<std::ptrdiff_t>(at),
                  old.begin() + static_cast<std::ptrdiff_t>(at) + ts.x,
                  old.begin() + static_cast<std::ptrdiff_t>(k));
      k += static_cast<std::size_t>(ts.x);
    }
  old.resize(static_cast<std::size_t>(to.volume()));
}

// Step 1, shrink (unsigned fields without nearest sites): the box inside the region `r` holding
// every voxel the changes `near` can move, empty when none can; `old` receives its old values.
template <class T>
Box3i shrink_region(const RegionUpdate& u, const Grid<T>& field, const Box3i& r, const Box3i& near,
                    std::vector<T>& old) {
  // Open space far from everything needs no search: every voxel of r is in reach of an addition,
  // and no removal can raise a value there.
  const bool all_clamped = all_at_clamp(u.plan, field, r);
  if (all_clamped && u.kind == Changes::kRemovals) return {};
  // The box holding every voxel that can change (a superset found by a search that reads only
  // around the changes), then the exact test on its voxels. Once the search has covered a
  // sixteenth of the region, the rest is read faster front to back (its shells read a cache line
  // per voxel on their x faces): the whole region it is.
  const Box3i grown = all_clamped ? r : grow_affected(u.plan, field, r, near, r.volume() / 16);
  old.resize(static_cast<std::size_t>(grown.volume()));
  field.copy_to_dense(grown, old.data());
  const Box3i a = all_clamped ? r : affected_box(u.plan, grown, old, near, u.kind);
  if (!a.empty() && a != grown) keep_box(old, grown, a);
  return a;
}

// Step 2, site box: the sites the new values of `r` can depend on. `r` is the region `region`
// itself, or the box shrink_region() found inside it (`shrunk`).
template <class T>
Box3i site_box(const RegionUpdate& u, const Grid<T>& field, const Box3i& region, const Box3i& r,
               bool shrunk) {
  if (!shrunk) return Box3i{r.begin - u.reach, r.end + u.reach}.intersect(u.domain);
  if (u.additions_only) return r;  // the new sites alone, all inside the changed boxes
  // Sites farther than every new value of r cannot be anyone's nearest, nor sites beyond a face
  // farther than its own bound allows (NewValueBounds).
  Vec3i below = u.reach, above = u.reach;
  const NewValueBounds m = new_value_bound(u.plan, field, region, r);
  auto voxels = [](double d, double spacing) {
    return static_cast<int>(std::floor(d / spacing + 1e-9));
  };  // d is a bound already
  for (int k = 0; k < 3; ++k) {
    const double s = u.plan.spacing[static_cast<std::size_t>(k)];
    if (std::isfinite(m.all)) below[k] = above[k] = std::min(u.reach[k], voxels(m.all, s));
    if (std::isfinite(m.lo_face[static_cast<std::size_t>(k)]))
      below[k] = std::min(below[k], 1 + voxels(m.lo_face[static_cast<std::size_t>(k)], s));
    if (std::isfinite(m.hi_face[static_cast<std::size_t>(k)]))
      above[k] = std::min(above[k], 1 + voxels(m.hi_face[static_cast<std::size_t>(k)], s));
  }
  const Box3i in = Box3i{r.begin - below, r.end + above}.intersect(u.domain);
  // Air is no site: the box needs to hold r and the solid voxels around it only (after a carve in
  // open air, often little more than r).
  return solid_bounds(u.occupancy, in).unite(r);
}

// Step 3, recompute: the new values of `r` (and nearest sites, when `sites` is not null) from the
// sites in `in`, densely. Additions take the distance to the new sites in `near`, then the minimum
// with the old values.
template <class T>
void recompute(const RegionUpdate& u, const Box3i& in, const Box3i& r, const Box3i& near,
               const std::vector<T>& old, std::vector<T>& values, std::vector<SiteOffset>* sites) {
  values.resize(static_cast<std::size_t>(r.volume()));
  if (sites) sites->resize(static_cast<std::size_t>(r.volume()));
  compute_region<T>(u.occupancy, u.plan, in, r, values.data(), sites ? sites->data() : nullptr,
                    u.additions_only ? &near : nullptr);
  if (u.additions_only)
    for (std::size_t i = 0; i < values.size(); ++i) values[i] = std::min(values[i], old[i]);
}

// Step 4, write back: the recomputed box into the field's grids.
template <class T>
void write_back(const Box3i& r, const std::vector<T>& values, const std::vector<SiteOffset>& sites,
                Grid<T>& field, std::optional<Grid<SiteOffset>>& field_sites) {
  field.copy_from_dense(r, values.data());
  if (field_sites) field_sites->copy_from_dense(r, sites.data());
}

}  // namespace

}  // namespace detail

DynamicDistanceField::DynamicDistanceField(const World& world, DistanceOptions options)
    : world_(&world), options_(std::move(options)) {
  if (!options_.domain) {
    if (!world.voxels.bounds()) {
      throw InvalidArgument(
          "a dynamic distance field needs a fixed domain: bound the world or set options.domain");
    }
    options_.domain = *world.voxels.bounds();
  }
  reach_ = detail::field_reach(detail::make_field_plan(world.voxels, options_));
  rebuild();
  options_.interrupter = nullptr;  // it watched the first build; the field outlives it
}

void DynamicDistanceField::rebuild(Interrupter* interrupter) {
  DistanceOptions o = options_;
  if (interrupter) o.interrupter = interrupter;
  DistanceField fresh = compute_distance_field(world_->voxels, o);
  fresh.options.interrupter = nullptr;  // the field outlives the caller's interrupter
  fresh.frame = world_->frame;
  field_ = std::move(fresh);
}

DynamicDistanceField::UpdateStats DynamicDistanceField::update(const DirtyRegions& dirty) {
  UpdateStats stats;
  // Changes that neither removed nor added a solid voxel (repaints, recorded with
  // DirtyRegions::Track::kAnyChange) move no distance and no site: nothing to recompute.
  if (dirty.empty() || (!dirty.removes_solid() && !dirty.adds_solid())) return stats;
  const detail::FieldPlan plan = detail::make_field_plan(world_->voxels, options_);
  // Changes that only add sites (placing into air) can only lower an unsigned field: its new
  // value is min(old value, distance to the new sites), and the new sites lie in the changed
  // boxes. So the transform runs over the recomputed box with those boxes' voxels as its only
  // sites — no sites from the box grown by the reach. Encodings are monotone, so the minimum can be
  // taken on stored values. Signed fields (new solids need their distance to air) and nearest sites
  // (the tie rule) take the general path, as does anything that removed a solid voxel.
  const bool additions_only = !dirty.removes_solid() && !plan.is_signed && !field_.sites;
  // Unsigned fields without sites also shrink each region to the voxels the changes can move
  // (detail::grow_affected finds a box holding them, detail::affected_box tests its voxels), and
  // removals read only the sites their new values can reach (detail::new_value_bound). Signed
  // fields (a new solid changes distances inside it to air) and nearest sites keep the whole reach
  // box and read the sites up to the reach beyond it.
  const bool shrink = !plan.is_signed && !field_.sites;
  // `kind`: values can only rise after removals and only fall after additions.
  const detail::Changes kind = !dirty.adds_solid()      ? detail::Changes::kRemovals
                               : !dirty.removes_solid() ? detail::Changes::kAdditions
                                                        : detail::Changes::kBoth;
  const detail::RegionUpdate u{plan,   world_->voxels, *options_.domain,
                               reach_, kind,           additions_only};
  const std::vector<Box3i> changed = dirty.boxes();
  for (const detail::UpdateRegion& region :
       detail::update_regions(dirty, *options_.domain, reach_)) {
    std::visit(
        [&](auto& target) {
          using T = typename std::decay_t<decltype(target)>::value_type;
          // Scratch reused across updates (fresh buffers this size cost a page fault per 4 KiB).
          thread_local std::vector<T> old_scratch, values_scratch;
          std::vector<T>& old = old_scratch;
          std::vector<T>& values = values_scratch;
          Box3i r = region.out;  // the values recomputed
          Box3i near;            // the changes this region holds (shrink only)
          if (shrink) {
            near = detail::changes_near(changed, r, reach_);
            r = detail::shrink_region(u, target, region.out, near, old);
            if (r.empty()) return;  // nothing in the region can change
          }
          const Box3i in = detail::site_box(u, target, region.out, r, shrink);
          std::vector<SiteOffset> sites;
          detail::recompute(u, in, r, near, old, values, field_.sites ? &sites : nullptr);
          detail::write_back(r, values, sites, target, field_.sites);
          stats.voxels_recomputed += r.volume();
          stats.voxels_read += in.volume();
          ++stats.regions;
        },
        field_.values);
  }
  return stats;
}

}  // namespace voxfield
