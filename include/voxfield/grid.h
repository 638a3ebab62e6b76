// voxfield — Grid<T>: a sparse map of dense cubic chunks.
//
// The one data structure every voxfield algorithm works on (see docs/architecture.md).
//
//  * Space is cut into cubic chunks of edge `chunk_edge()` voxels, a power of two from 8 to 128
//    fixed at construction (default 32). Chunk c holds the voxels c*edge .. c*edge+edge-1.
//  * A chunk absent from the map reads as the grid's background value. A chunk whose voxels all
//    hold one value is stored as that value alone, with no voxel allocation ("uniform chunk").
//    Other chunks own a dense array of edge^3 values, x fastest, then y, then z.
//  * Each dense chunk counts the voxels holding one reference value (at first the value it was
//    expanded from), so set(), edit_chunk() and copy_from_dense() collapse a chunk that returns to
//    it in O(1). After writes of one other value, copy_from_dense() re-anchors the count on it (one
//    pass) and edit_chunk() checks for uniformity (a pass that stops at the first other voxel).
//    Other chunks that come out uniform are collapsed by compact() and by the bulk writers (fill,
//    generate_chunks, adopt_chunks) on what they touched.
//  * Coordinates are signed 32-bit, within the supported range kCoordRange (box.h). A grid may be
//    unbounded or bounded by a box inside that range; writes outside the bounds (or, unbounded,
//    outside the range) throw InvalidArgument and change nothing, reads outside return the
//    background.
//
// Thread safety: const member functions may run concurrently with each other; any write needs
// exclusive access. The parallel helpers run on voxfield's thread pool (see parallel.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/chunk_memory.h"
#include "voxfield/detail/assert.h"
#include "voxfield/error.h"

namespace voxfield {

// What a grid costs in memory. `voxels_covered` counts the voxels of every stored chunk (dense or
// uniform); voxels of absent chunks cost nothing and are not counted.
struct GridMemory {
  std::size_t bytes = 0;            // total heap + object bytes, best estimate
  std::size_t dense_chunks = 0;     // chunks owning edge^3 voxels
  std::size_t uniform_chunks = 0;   // chunks stored as a single value (never the background)
  std::int64_t voxels_covered = 0;  // (dense_chunks + uniform_chunks) * edge^3
  // bytes / voxels_covered; 0 for an empty grid.
  double bytes_per_voxel() const {
    return voxels_covered > 0 ? static_cast<double>(bytes) / static_cast<double>(voxels_covered)
                              : 0.0;
  }
};

// One chunk as seen by the iteration helpers. Either `voxels` points at edge^3 values (x fastest)
// or it is null and every voxel holds `uniform_value`.
template <class T>
struct ChunkView {
  Vec3i coord;      // chunk coordinate: voxel p lies in chunk floor(p / edge)
  Box3i box;        // the voxels this chunk covers
  const T* voxels;  // dense data, or nullptr for a uniform chunk
  T uniform_value;  // meaningful only when voxels == nullptr
  bool uniform() const { return voxels == nullptr; }
};

template <class T>
class Grid {
 public:
  using value_type = T;
  static constexpr int kMinChunkEdge = 8;
  static constexpr int kMaxChunkEdge = 128;
  static constexpr int kDefaultChunkEdge = 32;

  // Throws InvalidArgument unless chunk_edge is a power of two in [8, 128] and `bounds`, when
  // given, is non-empty.
  explicit Grid(int chunk_edge = kDefaultChunkEdge, T background = T{},
                std::optional<Box3i> bounds = std::nullopt);
  Grid(const Grid& other);
  Grid& operator=(const Grid& other);
  Grid(Grid&&) noexcept = default;
  Grid& operator=(Grid&&) noexcept = default;
  ~Grid() = default;

  int chunk_edge() const { return chunk_edge_; }
  int chunk_shift() const { return chunk_shift_; }  // log2(chunk_edge)
  std::int64_t chunk_volume() const {
    return std::int64_t{chunk_edge_} * chunk_edge_ * chunk_edge_;
  }
  T background() const { return background_; }
  const std::optional<Box3i>& bounds() const { return bounds_; }

  // Chunk holding voxel p, and the voxels a chunk covers.
  Vec3i chunk_of(Vec3i p) const {
    return {p.x >> chunk_shift_, p.y >> chunk_shift_, p.z >> chunk_shift_};
  }
  Box3i chunk_box(Vec3i chunk) const {
    const Vec3i lo{chunk.x * chunk_edge_, chunk.y * chunk_edge_, chunk.z * chunk_edge_};
    return {lo, lo + Vec3i::splat(chunk_edge_)};
  }

  // Whether chunk `coord` lies inside the supported coordinate range (computed without overflow
  // for any coordinate, e.g. one read from a file).
  bool chunk_in_range(Vec3i coord) const {
    for (int k = 0; k < 3; ++k) {
      const std::int64_t lo = std::int64_t{coord[k]} * chunk_edge_;
      if (!coord_in_range(lo) || !bound_in_range(lo + chunk_edge_)) return false;
    }
    return true;
  }

  // A copy of this grid in chunks of another edge and with other bounds (nullopt: unbounded); the
  // same voxels and background, those outside the new bounds dropped. Made chunk by chunk:
  // memory follows the content, not its bounding box. Throws InvalidArgument like the
  // constructor.
  Grid rechunked(int chunk_edge, std::optional<Box3i> bounds) const;

  // Per-voxel access. get() outside the bounds returns the background; set() outside throws.
  T get(Vec3i p) const;
  void set(Vec3i p, T value);

  // Sets every voxel of `box` to `value`. Throws InvalidArgument (changing nothing) when a bounded
  // grid does not contain the box. Whole chunks are stored as uniform values without allocation.
  void fill(const Box3i& box, T value);

  // Bulk copies between the grid and a dense array laid out x fastest, then y, then z, holding
  // box.volume() values. copy_to_dense reads the background where nothing is stored;
  // copy_from_dense throws InvalidArgument (changing nothing) when a bounded grid does not contain
  // the box.
  void copy_to_dense(const Box3i& box, T* out) const;
  void copy_from_dense(const Box3i& box, const T* in);

  // Smallest box holding every voxel whose value differs from the background (empty box if none).
  Box3i content_bounds() const;
  // Number of voxels whose value differs from the background.
  std::int64_t count_non_background() const;

  // Chunk bookkeeping.
  std::size_t chunk_count() const { return chunks_.size(); }
  GridMemory memory() const;
  // Collapses every dense chunk whose voxels all hold one value (to nothing when that value is the
  // background). Cost: one pass over the dense chunks.
  void compact();
  void clear() { chunks_.clear(); }

  // Calls f(const ChunkView<T>&) for every stored chunk, in unspecified order.
  void for_each_chunk(const std::function<void(const ChunkView<T>&)>& f) const;
  // The same on voxfield's thread pool; f must be safe to call concurrently.
  void parallel_for_each_chunk(const std::function<void(const ChunkView<T>&)>& f) const;
  // One chunk: its dense voxels, or the single value it holds (the background when absent).
  ChunkView<T> chunk_view(Vec3i coord) const {
    auto it = chunks_.find(coord);
    if (it == chunks_.end()) return {coord, chunk_box(coord), nullptr, background_};
    return {coord, chunk_box(coord), it->second.voxels.get(), it->second.uniform};
  }
  // Coordinates of every stored chunk, sorted by (z, y, x) so that results are deterministic.
  std::vector<Vec3i> chunk_coords() const;

  // Writes whole chunks in parallel: for every coordinate in `chunks`, calls
  // f(chunk_coord, T* voxels) with edge^3 values to fill (x fastest), replacing what was stored.
  // Chunks that come out uniform are collapsed. Throws InvalidArgument (changing nothing) when a
  // chunk lies outside a bounded grid's bounds; voxels of a chunk beyond the bounds are discarded
  // (reset to the background).
  void generate_chunks(const std::vector<Vec3i>& chunks, const std::function<void(Vec3i, T*)>& f);
  // Takes ownership of one dense array of edge^3 values (x fastest, from make_chunk_array) per
  // coordinate, replacing what was stored there; uniform ones are collapsed (scanned in parallel).
  // Same bounds rule as generate_chunks. Throws InvalidArgument (changing nothing) when the counts
  // or an array's size disagree.
  void adopt_chunks(const std::vector<Vec3i>& chunks, std::vector<ChunkArray<T>> data);

  // Writes the voxels of one dense chunk inside edit_chunk, by local index (x fastest). Writes keep
  // the chunk's O(1) collapse counter up to date, so an edit of a few voxels costs a few voxels —
  // no scan of the whole chunk afterwards.
  class ChunkEdit {
   public:
    T get(std::int64_t i) const { return voxels_[i]; }
    // Sets voxel i; returns whether its value changed.
    bool set(std::int64_t i, T value) {
      T& slot = voxels_[i];
      if (slot == value) return false;
      ref_count_ += (value == ref_ ? 1 : 0) - (slot == ref_ ? 1 : 0);
      if (writes_ == 0) first_ = value;
      one_value_ = one_value_ && value == first_;
      ++writes_;
      slot = value;
      return true;
    }
    std::int64_t writes() const { return writes_; }

   private:
    friend class Grid;
    ChunkEdit(T* voxels, T ref, std::int64_t ref_count)
        : voxels_(voxels), ref_(ref), ref_count_(ref_count) {}
    T* voxels_;
    T ref_;
    std::int64_t ref_count_;
    std::int64_t writes_ = 0;
    T first_{};
    bool one_value_ = true;
  };

  // Edits one chunk in place: makes it dense (expanding a uniform or absent chunk), calls
  // f(ChunkEdit&) to read and write its edge^3 voxels, and collapses the chunk again if it came
  // out uniform (known in O(1) from the chunk's collapse counter; when every write stored one value
  // other than the counter's, a check that stops at the first voxel holding another). Throws
  // InvalidArgument for a chunk wholly outside a bounded grid; f must not write voxels beyond the
  // bounds. If f throws, the voxels it wrote stay written (the chunk is left consistent).
  template <class F>
  void edit_chunk(Vec3i coord, F&& f);

  // Read-only accessor caching the last chunk looked up: ~5x faster than get() for coherent access.
  // Any write to the grid invalidates it.
  class ReadAccessor {
   public:
    explicit ReadAccessor(const Grid& grid) : grid_(&grid) {}
    T get(Vec3i p);

   private:
    const Grid* grid_;
    Vec3i cached_coord_{INT32_MIN, INT32_MIN, INT32_MIN};
    const void* cached_chunk_ = nullptr;  // const Chunk*, or nullptr when absent
  };

 private:
  struct Chunk {
    ChunkArray<T> voxels;  // null for a uniform chunk (chunk_memory.h: from the reuse cache)
    T uniform{};           // value of a uniform chunk
    // For dense chunks: a reference value (the one the chunk held when it was expanded, or the
    // one a later write re-anchored it on: compact(), a fill or a copy of one other value) and
    // ref_count, how many voxels hold it, so that writes can collapse the chunk in O(1).
    T ref{};
    std::int64_t ref_count = 0;
  };
  using ChunkMap = std::unordered_map<Vec3i, Chunk, Vec3iHash>;

  std::int64_t local_index(Vec3i p) const {
    const int mask = chunk_edge_ - 1;
    return (std::int64_t{p.z & mask} << (2 * chunk_shift_)) |
           (std::int64_t{p.y & mask} << chunk_shift_) | (p.x & mask);
  }
  void require_in_bounds(const Box3i& box, const char* what) const;
  void require_chunk_in_range(Vec3i coord, const char* what) const;
  Chunk& expand(Chunk& chunk);  // makes a uniform chunk dense
  void collapse_if_uniform(typename ChunkMap::iterator it);
  // A chunk whose every voxel equals its collapse counter's value (ref_count == volume) stored
  // as that one value (or dropped when it is the background).
  void collapse_to_ref(typename ChunkMap::iterator it);
  // Re-anchors a dense chunk's collapse counter on `value` (one pass counting it) and collapses
  // the chunk if every voxel holds it. Run after writes of a single value that differs from the
  // counter's: later writes of the same value then need no pass at all.
  void reanchor(typename ChunkMap::iterator it, T value);
  std::vector<Vec3i> chunks_overlapping(const Box3i& box) const;

  int chunk_edge_;
  int chunk_shift_;
  T background_;
  std::optional<Box3i> bounds_;
  ChunkMap chunks_;
};

}  // namespace voxfield

#include "voxfield/detail/grid_impl.h"
