// voxfield GPU backend — z-slabs of the exact transform and the tables of column neighbours that
// make each slab's values the larger problem's (Meijster, Roerdink & Hesselink 2000: the first pass
// runs along z and needs from the rest of a column only its nearest sites on either side; the
// others stay within slices). Two kinds of slab use them:
//   - a field that is itself a slab of a larger domain (an MPI rank's, distance_slab.h): its table,
//     uploaded from the host, sits at word 0 of the buffer;
//   - a region whose box is too large for the work buffers, whatever its reach (an unclamped field,
//     or a clamp too wide for split_regions' halos): cut into z-slabs, whose tables edt_columns
//     writes on the device after the uploaded one.
// Internal to the distance module's GPU half (gpu_distance.cpp).
#pragma once

#include <cstdint>
#include <vector>

#include "gpu/recorder.h"
#include "resident_world.h"
#include "voxfield/distance_slab.h"

namespace voxfield::gpu {

// How a region's box of sites is computed: whole (thickness 0), or in `count` z-slabs of
// `thickness` slices (the last maybe thinner), each at most `most_voxels` voxels.
struct ColumnSlabs {
  int thickness = 0;
  int count = 1;
  // The voxels one slab's work buffers hold, and the words of the slabs' neighbour tables.
  std::int64_t work_voxels = 0;
  std::int64_t table_words = 0;
};

// Whole when `in` holds at most `most_voxels` voxels; otherwise slabs as thick as fit. Throws
// InvalidArgument, naming the sizes and the device's range `range_bytes`, when not even one z-slice
// fits.
ColumnSlabs plan_column_slabs(const Box3i& in, std::int64_t most_voxels, std::uint64_t range_bytes,
                              std::uint64_t bytes_per_voxel);

// The device buffer of neighbour tables (binding 20 of the exact transform): the uploaded table of
// a field that is a slab of a larger domain, then room for the tables a run's regions compute.
class NeighbourTables {
 public:
  explicit NeighbourTables(Context::Impl& ctx);

  // The field over `field` is the slab of a larger domain that `n` describes (checked by the
  // caller): per column of the field's x-y extent, the nearest solid and air voxel below and above.
  void set_uploaded(const SlabNeighbours& n, const Box3i& field);
  bool has_uploaded() const { return uploaded_words_ > 0; }
  // The first word past the uploaded table: where computed tables start.
  std::uint32_t computed_base() const { return static_cast<std::uint32_t>(uploaded_words_); }

  // Before a run whose slabbed regions need at most `computed_words` words of tables: grows the
  // buffer (checked against one binding; InvalidArgument) and stages the uploaded table into `up`
  // until a run that carried it has been submitted.
  void stage(std::int64_t computed_words, Staging& up);
  std::size_t staged_bytes() const;  // of the uploaded table, by this run
  // Records the staged upload, if any, from `upload`.
  void record(Recorder& rec, Buffer& upload);
  // The run was submitted (and waited for): what it uploaded is on the device.
  void submitted();
  Buffer& buffer() { return buffer_; }

 private:
  Context::Impl& ctx_;
  std::vector<std::uint32_t> uploaded_;  // the uploaded table, kept for a grown buffer
  std::size_t uploaded_words_ = 0;
  Buffer buffer_;
  VkDeviceSize capacity_words_ = 0;
  bool pending_ = false;    // the uploaded table is staged in this run
  bool on_device_ = false;  // the uploaded table is in buffer_
  VkBufferCopy copy_{};
};

}  // namespace voxfield::gpu
