// voxfield — a rank's slab of a world kept with its exact field under edits (mpi.h).
//
// With clamp D, a voxel's value depends only on the sites within D (docs/distance.md, "Exactness
// with a clamp"): the sites within D of a slab lie within ceil(D / spacing_z) slices of it. So each
// rank keeps its slab and that many ghost slices on either side as a bounded world, applies every
// edit clipped to that box, and lets its own incremental field follow (on its executor: the CPU's
// DynamicDistanceField or its device's): over the slab its values are the whole field's (the ghost
// slices' values are not, and are never handed out).
//
// An unclamped f32 value may depend on any voxel of the domain, so no finite ghost holds what an
// edit reaches: each rank keeps its slab (and the slices the caller asks it to keep: kept_slices),
// edits change its materials, and refresh() runs the exact transform over the ranks again (its
// all-to-all passes) once edits changed any solid.
#include <algorithm>
#include <cmath>
#include <limits>

#include "collective.h"
#include "voxfield/distance_slab.h"
#include "voxfield/mpi.h"
#include "voxfield/world_io.h"

namespace voxfield::mpi {

int edit_ghost_slices(const DistanceOptions& options) {
  const double clamp = effective_clamp(options);
  if (!std::isfinite(clamp)) return 0;  // the slab alone: refresh() recomputes over the ranks
  const double slices = std::ceil(clamp / options.spacing[2]);
  return static_cast<int>(std::min<double>(slices, std::numeric_limits<std::int32_t>::max() / 4));
}

std::vector<double> edit_unit_weights(const Box3i& domain, int align,
                                      const std::vector<Edit>& edits, int ghost_slices) {
  const std::vector<Box3i> units = slab_units(domain, align);
  std::vector<double> weights(units.size(), 0.0);
  const std::int32_t g = std::max(ghost_slices, 0);
  for (const Edit& e : edits) {
    Box3i reach = brush_bounds(e.brush);
    if (reach.empty()) continue;
    for (int k = 0; k < 3; ++k) {
      reach.begin[k] = static_cast<std::int32_t>(std::max<std::int64_t>(
          std::int64_t{reach.begin[k]} - g, std::numeric_limits<std::int32_t>::min()));
      reach.end[k] = static_cast<std::int32_t>(std::min<std::int64_t>(
          std::int64_t{reach.end[k]} + g, std::numeric_limits<std::int32_t>::max()));
    }
    for (std::size_t u = 0; u < units.size(); ++u)
      weights[u] += static_cast<double>(reach.intersect(units[u]).volume());
  }
  return weights;
}

SlabEditor::SlabEditor(MPI_Comm comm, const SlabPartition& partition, const World& world,
                       const DistanceOptions& options, const Executor& executor, int kept_slices)
    : partition_(partition),
      options_(options),
      executor_(executor),
      dirty_(world.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  detail::collectively(comm, nullptr, [&] {
    detail::require_partition(comm, partition);
    const bool unclamped = !std::isfinite(effective_clamp(options));
    slab_ = partition.slab(rank);
    const int ghost = std::max(edit_ghost_slices(options), kept_slices);
    const Box3i& d = partition.domain;
    const auto z0 = static_cast<std::int32_t>(
        std::max<std::int64_t>(d.begin.z, std::int64_t{slab_.begin.z} - ghost));
    const auto z1 = static_cast<std::int32_t>(
        std::min<std::int64_t>(d.end.z, std::int64_t{slab_.end.z} + ghost));
    box_ = Box3i{{d.begin.x, d.begin.y, z0}, {d.end.x, d.end.y, z1}};
    // A bounded copy of the box: edits are clipped to it, and the field's domain is it.
    world_ = rechunk_world(world, world.voxels.chunk_edge(), box_, "rank " + std::to_string(rank));
    world_.palette = world.palette;
    // An unclamped field is computed by the first refresh(), after any edits the caller applies
    // first: one transform for a script, not one before it and one after.
    stale_ = unclamped;
    if (unclamped) return;
    DistanceOptions o = options;
    o.domain = box_;
    field_ = std::make_unique<IncrementalDistanceField>(executor_, world_, o);
  });
}

SlabEditor::Result SlabEditor::apply(const Edit& edit) {
  validate_edit(edit);  // the same refusal on every rank, whether the edit reaches it or not
  Result r;
  const EditResult e = apply_edit(world_, edit, &dirty_);
  r.voxels_changed = e.voxels_changed;
  r.reached = !dirty_.empty() || e.voxels_changed > 0;
  if (!dirty_.empty()) {
    if (field_) {
      const DynamicDistanceField::UpdateStats s = field_->update(dirty_);
      r.voxels_recomputed = s.voxels_recomputed;
    } else {
      stale_ = true;  // solids changed: the unclamped field waits for refresh()
    }
    dirty_.clear();
  }
  return r;
}

bool SlabEditor::refresh(MPI_Comm comm, ExchangeStats* stats, std::int64_t* voxels) {
  if (voxels) *voxels = 0;
  if (field_) return false;  // clamped: kept by apply() (every rank knows it from the options)
  int mine = stale_ ? 1 : 0, any = 0;
  {
    detail::CollectiveTimer timer(stats);
    MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, comm);
  }
  if (any == 0 && whole_) return false;
  whole_.reset();  // let go of the old field before the new one is built
  whole_ = compute_distance_field(comm, partition_, world_, options_, executor_, stats);
  stale_ = false;
  if (voxels) *voxels = slab_.volume();
  return true;
}

const DistanceField& SlabEditor::field() const {
  if (field_) return field_->field();
  if (!whole_)
    throw InvalidArgument(
        "mpi::SlabEditor: an unclamped field is computed by refresh(), which has not yet succeeded "
        "(call it first)");
  return *whole_;
}

}  // namespace voxfield::mpi
