// voxfield's programs — the refusals of a .vdb field output, given before the field is computed
// (voxfield field and voxfield-mpi field share it).
//
// encode_vdb_field refuses a field whose clamp leaves no band around a level set's surface, and one
// measured with a spacing out of proportion with its world's voxel size. Both follow from the
// options, the storage's encoding and the frame alone, so a field of the same options over two
// voxels — computed by the same code, in microseconds — meets the same refusal before a large one
// is computed, and the message names the output.
#pragma once

#include <string>

#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/vdb.h"
#include "voxfield/world.h"

namespace voxfield::app {

// Throws InvalidArgument naming `out` when a field of `options` in `frame` cannot be written as a
// .vdb.
inline void check_vdb_output(const std::string& out, const DistanceOptions& options,
                             const VoxelFrame& frame) {
  World probe;
  probe.voxels.set({0, 0, 0}, 1);
  DistanceOptions o = options;
  o.domain = Box3i{{0, 0, 0}, {2, 1, 1}};  // one solid voxel and one empty one
  o.nearest_sites = false;
  o.interrupter = nullptr;
  DistanceField field = compute_distance_field(probe, o);
  field.frame = frame;
  try {
    (void)vdb_field_background(field);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(out + ": " + e.what());
  }
}

}  // namespace voxfield::app
