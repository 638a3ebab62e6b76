// voxfield — LiveWorld: edits from any thread, consistent snapshots for readers.
#include "voxfield/live_world.h"

namespace voxfield {

LiveWorld::LiveWorld(World world, DistanceOptions options)
    : world_(std::move(world)), field_(world_, std::move(options)) {}

void LiveWorld::submit(const Edit& edit) {
  // Validated in the caller's thread, so that a bad edit is reported to whoever made it rather
  // than to the updating thread.
  validate_edit(edit);
  std::lock_guard lock(queue_mutex_);
  queue_.push_back(edit);
}

std::size_t LiveWorld::pending() const {
  std::lock_guard lock(queue_mutex_);
  return queue_.size();
}

LiveWorld::UpdateStats LiveWorld::update() {
  std::lock_guard one_at_a_time(update_mutex_);
  std::vector<Edit> edits;
  {
    std::lock_guard lock(queue_mutex_);
    edits.swap(queue_);
  }
  UpdateStats stats;
  if (edits.empty()) return stats;
  std::unique_lock exclusive(state_mutex_, std::defer_lock);
  {
    std::lock_guard turnstile(turnstile_);  // new readers wait here until the update is in
    exclusive.lock();
  }
  // A kept mesh needs every change (a repaint re-colours it); the field alone, only the solid
  // and air changes it depends on.
  DirtyRegions dirty(world_.voxels.chunk_edge(),
                     mesh_ ? DirtyRegions::Track::kAnyChange : DirtyRegions::Track::kOccupancy);
  try {
    for (const Edit& e : edits)
      stats.voxels_changed += apply_edit(world_, e, &dirty).voxels_changed;
    stats.edits = edits.size();
    stats.voxels_recomputed = field_.update(dirty).voxels_recomputed;
    if (mesh_) stats.remeshed_chunks = mesh_->update(dirty);
  } catch (...) {
    // The world may hold edits the mesh has not seen, and the mesh's field may be part new
    // (WorldMeshChunks::update): mesh the world again, so that readers never see a mesh of
    // another world; if that fails too, keep no mesh (read_mesh then says so).
    if (mesh_) {
      try {
        mesh_->rebuild();
      } catch (...) {
        mesh_.reset();
      }
    }
    throw;
  }
  return stats;
}

void LiveWorld::keep_mesh(const MeshOptions& options, Metric metric) {
  // No update runs meanwhile (update_mutex_), so the world stays as it is while the mesh is made
  // with readers still reading; they wait only for the swap.
  std::lock_guard one_at_a_time(update_mutex_);
  std::unique_ptr<WorldMeshChunks> fresh;
  {
    std::shared_lock read(state_mutex_);
    // An unbounded world's fixed volume is its field's domain.
    std::optional<Box3i> box;
    if (!world_.voxels.bounds()) box = field_.options().domain;
    fresh = std::make_unique<WorldMeshChunks>(world_, options, metric, box);
  }
  std::unique_lock exclusive(state_mutex_, std::defer_lock);
  {
    std::lock_guard turnstile(turnstile_);
    exclusive.lock();
  }
  mesh_ = std::move(fresh);
}

}  // namespace voxfield
