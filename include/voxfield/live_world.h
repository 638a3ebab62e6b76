// voxfield — a world and its distance field shared between threads.
//
// Any thread may submit() edits at any time; one thread at a time runs update(), which applies the
// queued edits in submission order and brings the field up to date incrementally (exactly, as
// DynamicDistanceField does). Readers — a renderer, an exporter — call read() and see a consistent
// snapshot: the world and the field after the same set of edits, never a half-updated chunk.
//
// Consistency comes from a reader-writer lock: read() holds it shared, update() holds it
// exclusively while it applies edits and recomputes, so a reader waits at most one update (a few
// milliseconds for local edits; see docs/benchmarks.md), and a turnstile keeps a stream of readers
// from starving the updates. Edits submitted while an update runs wait in the queue for the next
// one.
#pragma once

#include <memory>
#include <mutex>
#include <shared_mutex>
#include <vector>

#include "voxfield/dynamic_field.h"
#include "voxfield/error.h"
#include "voxfield/mesh_chunks.h"

namespace voxfield {

class LiveWorld {
 public:
  // Takes the world (bounded, or with options.domain) and computes its field.
  LiveWorld(World world, DistanceOptions options);
  LiveWorld(const LiveWorld&) = delete;
  LiveWorld& operator=(const LiveWorld&) = delete;

  // Queues an edit. Thread-safe; cheap (no voxel is touched until the next update()). Malformed
  // edits throw InvalidArgument here, in the submitting thread.
  void submit(const Edit& edit);

  struct UpdateStats {
    std::size_t edits = 0;               // edits applied
    std::int64_t voxels_changed = 0;     // voxels whose material changed
    std::int64_t voxels_recomputed = 0;  // field values recomputed
    std::vector<Vec3i> remeshed_chunks;  // the kept mesh's chunks re-meshed (keep_mesh)
  };
  // Applies every queued edit and updates the field. Safe to call from any thread; concurrent
  // calls run one after the other.
  UpdateStats update();

  // Calls f(const World&, const DistanceField&) with a consistent snapshot and returns its result.
  template <class F>
  auto read(F&& f) const {
    // Pass the turnstile first: while an update waits for the lock, new readers queue behind it,
    // so a reader that reads continuously (a render loop) cannot starve the updates.
    { std::lock_guard turnstile(turnstile_); }
    std::shared_lock lock(state_mutex_);
    return f(world_, field_.field());
  }

  std::size_t pending() const;

  // Meshes the world's surface now (WorldMeshChunks over the world's bounds, or over the field's
  // domain for an unbounded world; its errors) and keeps it through every later update. Calling
  // it again replaces the kept mesh.
  void keep_mesh(const MeshOptions& options, Metric metric = Metric::kEuclidean);
  // Calls f(const World&, const WorldMeshChunks&) with a consistent snapshot, as read() does.
  // InvalidArgument when no mesh is kept (none asked for, or an update threw and meshing the
  // world again failed too: keep_mesh() again).
  //
  // update() after a throw: the world holds the edits applied before it (their field may lag:
  // DynamicDistanceField::update), and a kept mesh is made again from the world as it is.
  template <class F>
  auto read_mesh(F&& f) const {
    { std::lock_guard turnstile(turnstile_); }
    std::shared_lock lock(state_mutex_);
    if (!mesh_) throw InvalidArgument("LiveWorld::read_mesh: no mesh is kept (call keep_mesh)");
    return f(world_, *mesh_);
  }

 private:
  mutable std::shared_mutex state_mutex_;  // guards world_ and field_
  mutable std::mutex turnstile_;           // held by an update while it waits for state_mutex_
  std::mutex update_mutex_;                // one update at a time
  mutable std::mutex queue_mutex_;         // guards queue_
  std::vector<Edit> queue_;
  World world_;
  DynamicDistanceField field_;
  std::unique_ptr<WorldMeshChunks> mesh_;  // bound to world_, when kept
};

}  // namespace voxfield
