// voxfield — incremental exact distance updates by local recomputation (see dynamic_field.h).
#include "voxfield/dynamic_field.h"

#include <cmath>

#include "../distance/field_plan.h"

namespace voxfield {
namespace {

Box3i grow(const Box3i& b, Vec3i by) { return {b.begin - by, b.end + by}; }

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

template <class T>
void copy_region(const Grid<T>& from, Grid<T>& to, const Box3i& box) {
  std::vector<T> dense(static_cast<std::size_t>(box.volume()));
  from.copy_to_dense(box, dense.data());
  to.copy_from_dense(box, dense.data());
}

}  // namespace

DynamicDistanceField::DynamicDistanceField(const World& world, DistanceOptions options)
    : world_(&world), options_(std::move(options)) {
  if (!options_.domain) {
    if (!world.voxels.bounds()) {
      throw InvalidArgument("a dynamic distance field needs a fixed domain: bound the world or set options.domain");
    }
    options_.domain = *world.voxels.bounds();
  }
  const detail::FieldPlan plan = detail::make_field_plan(world.voxels, options_);
  const Vec3i size = plan.domain.size();
  for (int k = 0; k < 3; ++k) {
    reach_[k] = std::isfinite(plan.clamp) ? static_cast<int>(std::min<double>(std::ceil(plan.clamp / plan.spacing[k]), size[k]))
                                          : size[k];
  }
  rebuild();
}

void DynamicDistanceField::rebuild() { field_ = compute_distance_field(world_->voxels, options_); }

DynamicDistanceField::UpdateStats DynamicDistanceField::update(const DirtyRegions& dirty) {
  UpdateStats stats;
  if (dirty.empty()) return stats;
  const Box3i domain = *options_.domain;
  std::vector<Box3i> reach_boxes;
  for (const Box3i& b : dirty.boxes()) {
    const Box3i r = grow(b, reach_).intersect(domain);
    if (!r.empty()) reach_boxes.push_back(r);
  }
  for (const Box3i& r : merge_overlapping(std::move(reach_boxes))) {
    // Values inside r depend on sites within the reach of r: compute on that box, keep r.
    DistanceOptions local = options_;
    local.domain = grow(r, reach_).intersect(domain);
    const DistanceField part = compute_distance_field(world_->voxels, local);
    std::visit(
        [&](auto& target) {
          using G = std::decay_t<decltype(target)>;
          copy_region(std::get<G>(part.values), target, r);
        },
        field_.values);
    if (field_.sites) copy_region(*part.sites, *field_.sites, r);
    stats.voxels_recomputed += r.volume();
    stats.voxels_read += local.domain->volume();
    ++stats.regions;
  }
  return stats;
}

}  // namespace voxfield
