// voxfield renderer — the render box as a flat table of chunks, so finding a voxel's chunk costs
// two shifts and an array index instead of the sparse grid's hash lookup, and the bricked layout
// of the voxels inside a chunk.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "voxfield/grid.h"

namespace voxfield::render_detail {

// A zero-initialised byte buffer for data read at random by every ray: 2 MiB aligned and, on
// Linux, backed by transparent huge pages when the system allows it, so a read rarely misses the
// TLB as well as the cache.
class LargeBuffer {
 public:
  LargeBuffer() = default;
  explicit LargeBuffer(std::size_t bytes);
  ~LargeBuffer();
  LargeBuffer(LargeBuffer&& o) noexcept
      : data_(std::exchange(o.data_, nullptr)),
        size_(std::exchange(o.size_, 0)),
        map_(std::exchange(o.map_, nullptr)),
        map_bytes_(std::exchange(o.map_bytes_, 0)) {}
  LargeBuffer& operator=(LargeBuffer&& o) noexcept {
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
    std::swap(map_, o.map_);
    std::swap(map_bytes_, o.map_bytes_);
    return *this;
  }
  std::uint8_t* data() { return data_; }
  const std::uint8_t* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
  void* map_ = nullptr;  // the mapping data_ lies in (Linux)
  std::size_t map_bytes_ = 0;
};

class ChunkTable {
 public:
  ChunkTable() = default;
  ChunkTable(const Box3i& box, int chunk_edge);

  const Box3i& box() const { return box_; }
  int chunk_edge() const { return edge_; }
  int shift() const { return shift_; }
  std::size_t chunk_count() const { return static_cast<std::size_t>(dims_.x) * dims_.y * dims_.z; }
  // The chunks that `boxes` touch inside box(), each once, in index order.
  std::vector<std::size_t> chunks_touching(std::span<const Box3i> boxes) const;

  // Chunk index of voxel v, which must lie in box().
  std::size_t chunk_index(Vec3i v) const {
    return (static_cast<std::size_t>((v.z >> shift_) - first_.z) * dims_.y +
            static_cast<std::size_t>((v.y >> shift_) - first_.y)) *
               dims_.x +
           static_cast<std::size_t>((v.x >> shift_) - first_.x);
  }
  // Index of v inside its chunk (the Grid's layout: x fastest).
  std::uint32_t local_index(Vec3i v) const {
    const int m = edge_ - 1;
    return (static_cast<std::uint32_t>(v.z & m) << (2 * shift_)) |
           (static_cast<std::uint32_t>(v.y & m) << shift_) | static_cast<std::uint32_t>(v.x & m);
  }
  // Index of v inside its chunk in the renderer's bricked layout: 4x4x4 bricks of 64 bytes (one
  // cache line), so the voxels a ray and its neighbouring pixels read near each other share lines
  // in all three directions, not only along x rows.
  std::uint32_t brick_index(Vec3i v) const {
    const int m = edge_ - 1, bs = shift_ - 2;  // bricks per chunk edge: 2^bs
    const auto bx = static_cast<std::uint32_t>((v.x & m) >> 2),
               by = static_cast<std::uint32_t>((v.y & m) >> 2),
               bz = static_cast<std::uint32_t>((v.z & m) >> 2);
    const std::uint32_t brick = (((bz << bs) | by) << bs) | bx;
    return (brick << 6) | (static_cast<std::uint32_t>(v.z & 3) << 4) |
           (static_cast<std::uint32_t>(v.y & 3) << 2) | static_cast<std::uint32_t>(v.x & 3);
  }
  // The voxel box of chunk c (by chunk index), clipped to nothing: whole chunks.
  Box3i chunk_box_of(Vec3i v) const {
    const Vec3i lo{(v.x >> shift_) << shift_, (v.y >> shift_) << shift_, (v.z >> shift_) << shift_};
    return {lo, lo + Vec3i::splat(edge_)};
  }
  Vec3i first_chunk() const { return first_; }
  Vec3i chunk_dims() const { return dims_; }

  // Chunk coordinate of chunk index i.
  Vec3i chunk_coord(std::size_t i) const {
    const auto nx = static_cast<std::size_t>(dims_.x), ny = static_cast<std::size_t>(dims_.y);
    return {first_.x + static_cast<int>(i % nx), first_.y + static_cast<int>((i / nx) % ny),
            first_.z + static_cast<int>(i / (nx * ny))};
  }

 private:
  Box3i box_;
  int edge_ = 0, shift_ = 0;
  Vec3i first_{0, 0, 0}, dims_{0, 0, 0};
};

}  // namespace voxfield::render_detail
