// voxfield — vector fields from voxel worlds: "flow around obstacles" for particles and AI.
//
// At every voxel of a box, the direction away from the nearest solid voxel and a strength from the
// exact Euclidean distance d to it: s = 1 - d / reach where d < reach, else zero — the model of
// docs/vectors.md with every solid voxel a source of radius `reach` (a solid voxel itself reads
// strength 1, direction 0). It comes straight from the nearest-site field (distance.h), and a
// WorldVectorField keeps it current under edits through the incremental field (dynamic_field.h),
// re-encoding only the voxels an edit can change.
#pragma once

#include <cstdint>

#include "voxfield/dynamic_field.h"
#include "voxfield/edit.h"
#include "voxfield/vectors.h"

namespace voxfield {

// The vector volume of a world box: axis-aligned, one texel per voxel (voxel v spans [v, v + 1),
// so texel (i, j, k) is centred at box.begin + (i, j, k) + 1/2).
VectorVolume world_vector_volume(const Box3i& box);

// The texture over `box` of a Euclidean field computed with nearest sites and a clamp of at least
// `reach` (InvalidArgument otherwise, or for a box outside the field's domain or a reach that is
// not finite and > 0).
VectorTexture vectors_from_field(const DistanceField& field, const Box3i& box, double reach,
                                 VectorStorage storage);

class WorldVectorField {
 public:
  // Binds to `world` (which must outlive this object) and computes the field over `box` (its
  // domain: solids outside it are not seen). Throws InvalidArgument for an empty box, a reach that
  // is not finite and in (0, 2^14), ResourceLimitError past the memory limit.
  WorldVectorField(const World& world, const Box3i& box, double reach, VectorStorage storage);

  // After edits of the world recorded in `dirty`: the incremental field's update, then the texels
  // of the changed boxes grown by the reach, each texel once. Returns the texels re-encoded.
  std::int64_t update(const DirtyRegions& dirty);

  const VectorVolume& volume() const { return volume_; }
  const VectorTexture& texture() const { return texture_; }
  const DistanceField& field() const { return field_.field(); }
  double reach() const { return reach_; }

 private:
  void encode(const Box3i& region);

  Box3i box_;
  double reach_;
  VectorVolume volume_;
  DynamicDistanceField field_;
  VectorTexture texture_;
};

}  // namespace voxfield
