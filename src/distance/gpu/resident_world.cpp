// voxfield GPU backend — a world's page table and brick pool on the device (resident_world.h).
#include "resident_world.h"

#include <algorithm>
#include <cstring>

#include "gpu/split_buffer.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

}  // namespace

VkDeviceSize Staging::add(const void* data, std::size_t n) {
  const VkDeviceSize offset = (bytes.size() + 15) / 16 * 16;
  bytes.resize(offset + n);
  if (n > 0) std::memcpy(bytes.data() + offset, data, n);
  return offset;
}

ResidentWorld::ResidentWorld(Context::Impl& ctx, const World& world, const Box3i& box)
    : ctx_(ctx), world_(world), shift_(world.voxels.chunk_shift()) {
  origin_ = {box.begin.x >> shift_, box.begin.y >> shift_, box.begin.z >> shift_};
  const Vec3i last{(box.end.x - 1) >> shift_, (box.end.y - 1) >> shift_, (box.end.z - 1) >> shift_};
  dims_ = last - origin_ + Vec3i::splat(1);
  chunk_bytes_ = static_cast<std::size_t>(world.voxels.chunk_volume());
  // (4 bytes a chunk, bound whole: the fields on it, a byte a voxel, outgrow a binding first.)
  pages_.assign(static_cast<std::size_t>(dims_.x) * dims_.y * dims_.z,
                L::VF_UNIFORM);  // all air until synced
  pages_buf_ = Buffer(ctx, pages_.size() * 4, kStorage, false);
  // A pool of one brick to begin with: a world of uniform chunks alone still binds one.
  bricks_buf_ = Buffer(ctx, chunk_bytes_, kStorage, false);
  slot_capacity_ = 1;
}

bool ResidentWorld::covers(const Box3i& box) const {
  const Vec3i origin{box.begin.x >> shift_, box.begin.y >> shift_, box.begin.z >> shift_};
  const Vec3i last{(box.end.x - 1) >> shift_, (box.end.y - 1) >> shift_, (box.end.z - 1) >> shift_};
  return !box.empty() && origin == origin_ && last - origin + Vec3i::splat(1) == dims_;
}

void ResidentWorld::describe(L::Header& h) const {
  h.chunk_origin = {origin_.x, origin_.y, origin_.z, 0};
  h.chunk_dims = {dims_.x, dims_.y, dims_.z, dims_.x * dims_.y * dims_.z};
  h.chunk_edge = static_cast<std::uint32_t>(world_.voxels.chunk_edge());
  h.chunk_shift = static_cast<std::uint32_t>(shift_);
  h.chunk_words = static_cast<std::uint32_t>(chunk_bytes_ / 4);
}

std::vector<Vec3i> ResidentWorld::all_chunks() const {
  std::vector<Vec3i> chunks;
  for (int z = 0; z < dims_.z; ++z)
    for (int y = 0; y < dims_.y; ++y)
      for (int x = 0; x < dims_.x; ++x) chunks.push_back(origin_ + Vec3i{x, y, z});
  return chunks;
}

std::size_t ResidentWorld::page_index(Vec3i c) const {
  const Vec3i r = c - origin_;
  return (static_cast<std::size_t>(r.z) * dims_.y + r.y) * dims_.x + r.x;
}

void ResidentWorld::stage(const std::vector<Vec3i>& chunks, Staging& up, Uploads& uploads) {
  struct Change {
    std::size_t page;
    const std::uint8_t* voxels;
    std::uint8_t value;
  };
  std::vector<Change> changes;
  for (const Vec3i& c : chunks) {
    if (c.x < origin_.x || c.y < origin_.y || c.z < origin_.z) continue;
    const Vec3i r = c - origin_;
    if (r.x >= dims_.x || r.y >= dims_.y || r.z >= dims_.z) continue;
    const ChunkView<std::uint8_t> v = world_.voxels.chunk_view(c);
    changes.push_back({page_index(c), v.voxels, v.uniform_value});
  }
  // One change per page (a chunk named twice is staged once), the chunks that became uniform
  // first: the slots they free are there for the chunks that became dense, so the slots the sync
  // needs beyond the free list are counted exactly (a pool at the range is not refused for them).
  std::sort(changes.begin(), changes.end(),
            [](const Change& a, const Change& b) { return a.page < b.page; });
  changes.erase(std::unique(changes.begin(), changes.end(),
                            [](const Change& a, const Change& b) { return a.page == b.page; }),
                changes.end());
  std::stable_partition(changes.begin(), changes.end(),
                        [](const Change& ch) { return ch.voxels == nullptr; });
  std::uint32_t new_dense = 0, freed = 0;
  for (const Change& ch : changes) {
    const bool had_slot = (pages_[ch.page] & L::VF_UNIFORM) == 0;
    if (ch.voxels && !had_slot) ++new_dense;
    if (!ch.voxels && had_slot) ++freed;
  }
  const std::uint32_t reusable = static_cast<std::uint32_t>(free_slots_.size()) + freed;
  const std::uint32_t needed = used_slots_ + (new_dense > reusable ? new_dense - reusable : 0);
  if (needed > slot_capacity_) {
    // Grow the pool (amortised doubling, within what the shaders bind: split_buffer.h's
    // windows); the old bricks are copied over on the GPU. A pool past that is refused before
    // anything changes.
    check_split_binding(
        ctx_, static_cast<VkDeviceSize>(needed) * chunk_bytes_,
        "GPU: the brick pool of the world's " + std::to_string(needed) + " chunks holding voxels");
    const std::uint64_t most = split_capacity_bytes(ctx_) / chunk_bytes_;
    const std::uint32_t capacity = static_cast<std::uint32_t>(std::min<std::uint64_t>(
        std::max<std::uint32_t>(needed + needed / 4 + 8, slot_capacity_ * 2), most));
    Buffer grown(ctx_, static_cast<VkDeviceSize>(capacity) * chunk_bytes_, kStorage, false);
    if (used_slots_ > 0) {
      uploads.old_pool_bytes = static_cast<VkDeviceSize>(used_slots_) * chunk_bytes_;
      uploads.old_pool.emplace(std::move(bricks_buf_));
    }
    bricks_buf_ = std::move(grown);
    slot_capacity_ = capacity;
  }
  for (const Change& ch : changes) {
    std::uint32_t& entry = pages_[ch.page];
    const bool had_slot = (entry & L::VF_UNIFORM) == 0;
    std::uint32_t next;
    if (!ch.voxels) {
      if (had_slot) free_slots_.push_back(entry);
      next = L::VF_UNIFORM | ch.value;
    } else {
      std::uint32_t slot;
      if (had_slot) {
        slot = entry;
      } else if (!free_slots_.empty()) {
        slot = free_slots_.back();
        free_slots_.pop_back();
      } else {
        slot = used_slots_++;
      }
      // The pool was sized above; a slot beyond it would be an out-of-range GPU copy.
      if (slot >= slot_capacity_)
        throw Error("GPU: internal error: brick pool slot " + std::to_string(slot) +
                    " beyond its capacity " + std::to_string(slot_capacity_));
      uploads.brick_copies.push_back({up.add(ch.voxels, chunk_bytes_),
                                      static_cast<VkDeviceSize>(slot) * chunk_bytes_,
                                      chunk_bytes_});
      next = slot;
    }
    if (next != entry || first_sync_) {
      entry = next;
      uploads.page_copies.push_back({up.add(&entry, 4), ch.page * 4, 4});
    }
  }
  first_sync_ = false;
}

void ResidentWorld::record(Recorder& rec, Buffer& upload, Uploads& uploads, Buffer* header_buffer,
                           std::span<const VkBufferCopy> header) {
  // A grown pool's old bricks first: changed chunks may be written over them. (The recorder
  // orders these copies after the previous submission's passes, which read what they overwrite.)
  if (uploads.old_pool) rec.copy(*uploads.old_pool, 0, bricks_buf_, 0, uploads.old_pool_bytes);
  rec.copy({{&upload, header_buffer ? header_buffer : &pages_buf_,
             header_buffer ? header : std::span<const VkBufferCopy>()},
            {&upload, &pages_buf_, uploads.page_copies},
            {&upload, &bricks_buf_, uploads.brick_copies}});
}

}  // namespace voxfield::gpu
