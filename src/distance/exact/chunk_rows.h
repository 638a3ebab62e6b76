// voxfield — the exact transform's view of chunked storage (internal): the output chunks of a
// chunk-aligned box addressed by rows, the world's chunks as rows of solid flags, and the pieces
// of a domain row that fall in each chunk column.
//
// The whole-field transform (whole_field.cpp; Meijster, Roerdink & Hesselink 2000) keeps g, the
// z pass's result, in the output chunks themselves, so no volume-sized scratch is needed: every
// pass reads and writes rows of chunk-edge voxels through these views.
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <memory>
#include <vector>

#include "../field_plan.h"
#include "voxfield/chunk_memory.h"

namespace voxfield::detail::exact {

using Plan = FieldPlan;

// Chunk arrays covering a chunk-aligned box, addressed by voxel.
template <class T>
struct ChunkedVolume {
  Box3i box;  // chunk-aligned
  int edge = 0, shift = 0;
  Vec3i nchunks;
  std::vector<Vec3i> coords;
  std::vector<ChunkArray<T>> chunks;

  ChunkedVolume(const Box3i& aligned, int chunk_edge) : box(aligned), edge(chunk_edge) {
    shift = std::countr_zero(static_cast<unsigned>(chunk_edge));
    nchunks = {box.size().x >> shift, box.size().y >> shift, box.size().z >> shift};
    const Vec3i c0{box.begin.x >> shift, box.begin.y >> shift, box.begin.z >> shift};
    const std::size_t n = static_cast<std::size_t>(nchunks.x) * nchunks.y * nchunks.z;
    coords.reserve(n);
    chunks.resize(n);
    for (int z = 0; z < nchunks.z; ++z)
      for (int y = 0; y < nchunks.y; ++y)
        for (int x = 0; x < nchunks.x; ++x) coords.push_back(c0 + Vec3i{x, y, z});
    const std::size_t volume = std::size_t{1} << (3 * shift);
    for (auto& c : chunks) c = make_chunk_array<T>(volume);
  }
  // Pointer to the `edge` voxels of the row (chunk column cx, y, z), x fastest.
  T* row(int cx, int y, int z) {
    const int ly = y - box.begin.y, lz = z - box.begin.z;
    const std::size_t ci =
        (static_cast<std::size_t>(lz >> shift) * nchunks.y + (ly >> shift)) * nchunks.x + cx;
    const int mask = edge - 1;
    return chunks[ci].get() + (static_cast<std::size_t>(lz & mask) << (2 * shift)) +
           (static_cast<std::size_t>(ly & mask) << shift);
  }
};

// Rows of the world's chunks as 0/1 solid flags, for the same chunk-aligned box.
class SolidRows {
 public:
  SolidRows(const Grid<std::uint8_t>& g, const Box3i& aligned) : box_(aligned) {
    edge_ = g.chunk_edge();
    shift_ = g.chunk_shift();
    nchunks_ = {box_.size().x >> shift_, box_.size().y >> shift_, box_.size().z >> shift_};
    const Vec3i c0{box_.begin.x >> shift_, box_.begin.y >> shift_, box_.begin.z >> shift_};
    std::fill(std::begin(zeros_), std::end(zeros_), 0);
    std::fill(std::begin(ones_), std::end(ones_), 1);
    for (int z = 0; z < nchunks_.z; ++z)
      for (int y = 0; y < nchunks_.y; ++y)
        for (int x = 0; x < nchunks_.x; ++x) {
          const ChunkView<std::uint8_t> v = g.chunk_view(c0 + Vec3i{x, y, z});
          chunks_.push_back(v.voxels ? v.voxels : (v.uniform_value ? ones_ : zeros_));
          dense_.push_back(v.voxels != nullptr);
        }
  }
  // Material row (dense chunks) or a row of 0/1 (uniform chunks): non-zero means solid.
  const std::uint8_t* row(int cx, int y, int z) const {
    const int ly = y - box_.begin.y, lz = z - box_.begin.z;
    const std::size_t ci =
        (static_cast<std::size_t>(lz >> shift_) * nchunks_.y + (ly >> shift_)) * nchunks_.x + cx;
    if (!dense_[ci]) return chunks_[ci];
    const int mask = edge_ - 1;
    return chunks_[ci] + (static_cast<std::size_t>(lz & mask) << (2 * shift_)) +
           (static_cast<std::size_t>(ly & mask) << shift_);
  }

 private:
  Box3i box_;
  int edge_, shift_;
  Vec3i nchunks_;
  std::vector<const std::uint8_t*> chunks_;
  std::vector<char> dense_;
  std::uint8_t zeros_[128], ones_[128];
};

// Calls fn(cx, local_x0, count, x_offset) for the pieces of the domain row that fall in each chunk
// column: local_x0 is the first voxel within the chunk row, x_offset its index within the domain.
template <class Fn>
void for_each_row_segment(const Plan& p, int edge, int shift, Fn&& fn) {
  const int bx = p.domain.begin.x, ex = p.domain.end.x, ax = p.aligned.begin.x;
  for (int cx = (bx - ax) >> shift; cx <= (ex - 1 - ax) >> shift; ++cx) {
    const int c0 = ax + (cx << shift);
    const int x0 = std::max(bx, c0), x1 = std::min(ex, c0 + edge);
    fn(cx, x0 - c0, x1 - x0, x0 - bx);
  }
}

}  // namespace voxfield::detail::exact
