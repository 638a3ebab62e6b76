// voxfield GPU backend — a world's voxels resident on the device: one page table over the chunks
// of a box and one brick pool (shaders/layout.h). A chunk stored voxel by voxel on the host has a
// brick (4 voxels per 32-bit word, x fastest); a uniform chunk is its page entry alone, so the
// pool grows with the content, not with the box. Every field computed from the world reads it
// (gpu_distance.cpp), and the render module packs its cells from it: one copy of the world per
// device, however many fields are derived from it.
#pragma once

#include <optional>
#include <vector>

#include "gpu/recorder.h"
#include "shaders/layout.h"
#include "voxfield/world.h"

namespace voxfield::gpu {

// Bytes for an upload buffer, each piece 16-byte aligned.
struct Staging {
  std::vector<std::uint8_t> bytes;
  VkDeviceSize add(const void* data, std::size_t n);
};

class ResidentWorld {
 public:
  // The page table of the chunks `box` touches, all uniform air until synced; a pool of one brick.
  ResidentWorld(Context::Impl& ctx, const World& world, const Box3i& box);
  ResidentWorld(const ResidentWorld&) = delete;
  ResidentWorld& operator=(const ResidentWorld&) = delete;

  // What a sync copies from the upload buffer, and the old pool a grown one copies its bricks
  // from (kept alive until the copy out of it has run).
  struct Uploads {
    std::vector<VkBufferCopy> page_copies, brick_copies;
    std::optional<Buffer> old_pool;
    VkDeviceSize old_pool_bytes = 0;
  };
  // Stages the page entries and bricks of `chunks` (those inside the page table) as the world
  // holds them now; grows the pool when they need more bricks than it has free.
  void stage(const std::vector<Vec3i>& chunks, Staging& up, Uploads& uploads);
  // Records the staged copies (a grown pool's old bricks first) — `header` too, when given, in
  // the same step.
  void record(Recorder& rec, Buffer& upload, Uploads& uploads, Buffer* header_buffer,
              std::span<const VkBufferCopy> header);

  // After a run that failed: the next stage() sends every page entry it is given again (and
  // every brick, as always), whatever the host counts as sent.
  void resync() { first_sync_ = true; }

  // Every chunk of the page table.
  std::vector<Vec3i> all_chunks() const;
  // The page table's part of a field's header.
  void describe(layout::Header& h) const;
  // Whether the page table is exactly the chunks `box` touches.
  bool covers(const Box3i& box) const;
  Vec3i chunk_origin() const { return origin_; }
  Vec3i chunk_dims() const { return dims_; }
  const World& world() const { return world_; }
  Buffer& pages() { return pages_buf_; }
  Buffer& bricks() { return bricks_buf_; }

 private:
  std::size_t page_index(Vec3i c) const;

  Context::Impl& ctx_;
  const World& world_;
  int shift_ = 0;
  Vec3i origin_{0, 0, 0}, dims_{0, 0, 0};
  std::size_t chunk_bytes_ = 0;
  std::vector<std::uint32_t> pages_;  // the host's copy of the page table
  std::vector<std::uint32_t> free_slots_;
  std::uint32_t used_slots_ = 0, slot_capacity_ = 0;
  bool first_sync_ = true;
  Buffer pages_buf_, bricks_buf_;
};

}  // namespace voxfield::gpu
