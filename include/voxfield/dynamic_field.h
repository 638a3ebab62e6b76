// voxfield — distance fields that follow a world through its edits.
//
// A DynamicDistanceField is bound to a World and a set of DistanceOptions. After edits recorded in
// DirtyRegions, update() recomputes only what they can change, with the same exact kernel as a
// full computation, so the field stays bit-identical to a full rebuild:
//
//   with clamp D, a voxel's value depends only on sites within distance D, so an edit in box B
//   changes values only inside B grown by D (the "reach"), and recomputing those needs the sites
//   inside B grown by 2D. Integer storage clamps at its range even without an explicit D.
//
// Unsigned fields without nearest sites do much less (docs/distance.md, "Incremental updates"):
// only voxels whose old distance reaches the edit can change, and the box holding them is found
// by a search that reads around the edit; placements take the distance to the new sites alone;
// carves read only the sites their new values can reach (a hole in solid ground: a few voxels).
//
// Unclamped f32 fields have an unbounded reach: an update may have to recompute the whole domain
// (cost proportional to the world, not the edit) — unsigned ones only where values really move.
// Clamp the field to bound every update.
#pragma once

#include "voxfield/distance.h"
#include "voxfield/edit.h"

namespace voxfield {

class DynamicDistanceField {
 public:
  // Binds to `world` (which must outlive this object) and computes the field. The domain must
  // stay fixed: the world must be bounded, or options.domain given; otherwise InvalidArgument.
  DynamicDistanceField(const World& world, DistanceOptions options);

  struct UpdateStats {
    std::int64_t voxels_recomputed = 0;  // voxels whose values were recomputed
    std::int64_t voxels_read =
        0;            // voxels the kernel ran over (recomputed boxes and the sites around them)
    int regions = 0;  // merged boxes recomputed
  };

  // Recomputes the whole field, reporting to `interrupter` when given (as compute_distance_field
  // does). Strong guarantee: if it throws (Cancelled included) the field is the one before.
  void rebuild(Interrupter* interrupter = nullptr);
  // Recomputes what the recorded changes can affect (nothing when none removed or added a solid
  // voxel: repaints). The caller clears `dirty` afterwards.
  // Not the strong exception guarantee: the field is written region by region, so if update()
  // throws (out of memory, while recomputing or storing a region) the regions before hold their
  // new values, the one being stored may hold some, the rest their old ones — a valid field, but
  // no longer exact for the world. rebuild() makes it exact again.
  UpdateStats update(const DirtyRegions& dirty);

  const DistanceField& field() const { return field_; }
  const DistanceOptions& options() const { return options_; }
  // How far, in voxels along each axis, a change can move values (the domain size when unbounded).
  Vec3i reach() const { return reach_; }

 private:
  const World* world_;
  DistanceOptions options_;
  Vec3i reach_;
  DistanceField field_;
};

}  // namespace voxfield
