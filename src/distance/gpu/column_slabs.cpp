// voxfield GPU backend — z-slabs of the exact transform and their column neighbours
// (column_slabs.h).
#include "column_slabs.h"

#include <algorithm>
#include <string>

#include "gpu/split_buffer.h"
#include "shaders/layout.h"

namespace voxfield::gpu {

ColumnSlabs plan_column_slabs(const Box3i& in, std::int64_t most_voxels, std::uint64_t range_bytes,
                              std::uint64_t bytes_per_voxel) {
  ColumnSlabs s;
  s.work_voxels = in.volume();
  if (in.volume() <= most_voxels) return s;
  const std::int64_t slice = static_cast<std::int64_t>(in.size().x) * in.size().y;
  if (slice > most_voxels)
    throw InvalidArgument(
        "GPU: a region of " + std::to_string(in.volume()) + " voxels needs work buffers of " +
        std::to_string(static_cast<std::uint64_t>(in.volume()) * bytes_per_voxel) +
        " bytes, more than this device's storage-buffer range (" + std::to_string(range_bytes) +
        "), and so does one z-slice of it (" + std::to_string(in.size().x) + " x " +
        std::to_string(in.size().y) + " voxels), the thinnest slab the transform can be cut into");
  s.thickness = static_cast<int>(std::min<std::int64_t>(most_voxels / slice, in.size().z));
  s.count = (in.size().z + s.thickness - 1) / s.thickness;
  s.work_voxels = slice * s.thickness;
  s.table_words = 2 * slice * s.count;
  return s;
}

NeighbourTables::NeighbourTables(Context::Impl& ctx) : ctx_(ctx) {
  constexpr VkBufferUsageFlags kUsage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  buffer_ = Buffer(ctx, 16, kUsage, false);
}

void NeighbourTables::set_uploaded(const SlabNeighbours& n, const Box3i& field) {
  const std::size_t columns = n.solid_below.size();
  const std::int32_t z0 = field.begin.z;
  auto pack = [&](std::int32_t below, std::int32_t above) {
    const std::int32_t b = below == ColumnSites::kNoneHigh ? layout::VF_NO_NEIGHBOUR : below - z0;
    const std::int32_t a = above == ColumnSites::kNoneLow ? layout::VF_NO_NEIGHBOUR : above - z0;
    return (static_cast<std::uint32_t>(b) & 0xFFFFu) | (static_cast<std::uint32_t>(a) << 16);
  };
  uploaded_.resize(2 * columns);
  for (std::size_t c = 0; c < columns; ++c) {
    uploaded_[2 * c] = pack(n.solid_below[c], n.solid_above[c]);
    uploaded_[2 * c + 1] = pack(n.air_below[c], n.air_above[c]);
  }
  uploaded_words_ = uploaded_.size();
  on_device_ = false;  // the next stage() uploads the table
}

void NeighbourTables::stage(std::int64_t computed_words, Staging& up) {
  // What a run that failed before its submit left staged is staged again, in this run's upload.
  pending_ = false;
  const VkDeviceSize words = uploaded_words_ + static_cast<VkDeviceSize>(computed_words);
  if (words > capacity_words_) {
    check_whole_binding(
        ctx_, words * 4,
        "GPU: the column neighbours of the slabs of a field (" + std::to_string(words) + " words)");
    constexpr VkBufferUsageFlags kUsage =
        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    buffer_ = Buffer(ctx_, std::max<VkDeviceSize>(words * 4, 16), kUsage, false);
    capacity_words_ = words;
    on_device_ = false;  // a new buffer holds nothing yet
  }
  if (!uploaded_.empty() && !on_device_) {
    const VkDeviceSize bytes = uploaded_.size() * 4;
    copy_ = VkBufferCopy{up.add(uploaded_.data(), bytes), 0, bytes};
    pending_ = true;
  }
}

std::size_t NeighbourTables::staged_bytes() const {
  return pending_ ? static_cast<std::size_t>(copy_.size) : 0;
}

void NeighbourTables::record(Recorder& rec, Buffer& upload) {
  if (pending_) rec.copy(upload, buffer_, std::span(&copy_, 1));
}

void NeighbourTables::submitted() {
  if (pending_) on_device_ = true;
  pending_ = false;
}

}  // namespace voxfield::gpu
