// voxfield GPU backend — the exact transform's work buffers (gpu_distance.cpp): the cost buffers,
// the envelope scans' scratch and the nearest sites of a region's passes. Internal to the
// distance module's GPU half.
#pragma once

#include <algorithm>

#include "gpu/vulkan_context.h"

namespace voxfield::gpu {

// The exact transform's work buffers: three cost buffers, the envelope scans' scratch, and the
// nearest sites of each cost buffer. Grown to the largest region a run computes, never shrunk;
// shared by the fields on one resident world, so the sites buffer is sized by the fields that
// carry sites alone.
struct WorkBuffers {
  static constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                               VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  Buffer cost[3], scratch_s, scratch_t, sites;
  VkDeviceSize bytes = 0;       // per cost buffer: 4 per voxel of the largest region computed
  VkDeviceSize site_bytes = 0;  // 24 per voxel of the largest region computed with nearest sites
  // The largest buffer a grow for a region of `needed` bytes per cost buffer would make.
  VkDeviceSize widest_after(VkDeviceSize needed, bool need_sites) const {
    return std::max({bytes, needed, need_sites ? std::max(site_bytes, 6 * needed) : site_bytes});
  }
  // The most voxels one region's box of sites may hold on a device binding at most `range` bytes
  // of a buffer.
  static std::int64_t most_region_voxels(VkDeviceSize range, bool need_sites) {
    return static_cast<std::int64_t>(range / 4 / (need_sites ? 6 : 1));
  }
  void grow(Context::Impl& ctx, VkDeviceSize needed, bool need_sites) {
    const VkDeviceSize n = std::max(bytes, needed);
    const VkDeviceSize s = need_sites ? std::max(site_bytes, 6 * needed) : site_bytes;
    if (n == bytes && s == site_bytes) return;
    // Made before any is kept: a failed allocation (GpuOutOfMemory) leaves the old set and sizes.
    WorkBuffers next;
    for (Buffer& b : next.cost) b = Buffer(ctx, n, kUsage, false);
    next.sites = Buffer(ctx, std::max<VkDeviceSize>(s, 16), kUsage, false);
    next.scratch_s = Buffer(ctx, n, kUsage, false);
    next.scratch_t = Buffer(ctx, n, kUsage, false);
    next.bytes = n;
    next.site_bytes = s;
    *this = std::move(next);
  }
};

}  // namespace voxfield::gpu
