// voxfield — Grid<T> implementation. Included by grid.h; not a public header on its own.
#pragma once

#include <algorithm>
#include <bit>
#include <cstring>
#include <string>
#include <tuple>

#include "voxfield/parallel.h"

namespace voxfield {

template <class T>
Grid<T>::Grid(int chunk_edge, T background, std::optional<Box3i> bounds)
    : chunk_edge_(chunk_edge), chunk_shift_(0), background_(background), bounds_(bounds) {
  if (chunk_edge < kMinChunkEdge || chunk_edge > kMaxChunkEdge ||
      !std::has_single_bit(static_cast<unsigned>(chunk_edge))) {
    throw InvalidArgument("chunk edge must be a power of two from 8 to 128, got " +
                          std::to_string(chunk_edge));
  }
  if (bounds_ && bounds_->empty()) {
    throw InvalidArgument("grid bounds " + to_string(*bounds_) + " are empty");
  }
  if (bounds_ && !kCoordRange.contains(*bounds_)) {
    throw InvalidArgument("grid bounds " + to_string(*bounds_) +
                          " reach outside the supported coordinate range " +
                          to_string(kCoordRange));
  }
  chunk_shift_ = std::countr_zero(static_cast<unsigned>(chunk_edge));
}

template <class T>
Grid<T>::Grid(const Grid& other)
    : chunk_edge_(other.chunk_edge_),
      chunk_shift_(other.chunk_shift_),
      background_(other.background_),
      bounds_(other.bounds_) {
  chunks_.reserve(other.chunks_.size());
  const std::int64_t n = chunk_volume();
  for (const auto& [coord, src] : other.chunks_) {
    Chunk copy;
    copy.uniform = src.uniform;
    copy.ref = src.ref;
    copy.ref_count = src.ref_count;
    if (src.voxels) {
      copy.voxels = make_chunk_array<T>(static_cast<std::size_t>(n));
      std::copy(src.voxels.get(), src.voxels.get() + n, copy.voxels.get());
    }
    chunks_.emplace(coord, std::move(copy));
  }
}

template <class T>
Grid<T>& Grid<T>::operator=(const Grid& other) {
  if (this != &other) *this = Grid(other);
  return *this;
}

template <class T>
void Grid<T>::require_in_bounds(const Box3i& box, const char* what) const {
  if (!bounds_ && !kCoordRange.contains(box)) {
    throw InvalidArgument(std::string(what) + ": box " + to_string(box) +
                          " reaches outside the supported coordinate range " +
                          to_string(kCoordRange));
  }
  if (bounds_ && !bounds_->contains(box)) {
    throw InvalidArgument(std::string(what) + ": box " + to_string(box) +
                          " reaches outside the grid bounds " + to_string(*bounds_));
  }
}

template <class T>
T Grid<T>::get(Vec3i p) const {
  auto it = chunks_.find(chunk_of(p));
  if (it == chunks_.end()) return background_;
  const Chunk& c = it->second;
  return c.voxels ? c.voxels[local_index(p)] : c.uniform;
}

template <class T>
typename Grid<T>::Chunk& Grid<T>::expand(Chunk& chunk) {
  const std::int64_t n = chunk_volume();
  chunk.voxels = make_chunk_array<T>(static_cast<std::size_t>(n));
  std::fill(chunk.voxels.get(), chunk.voxels.get() + n, chunk.uniform);
  chunk.ref = chunk.uniform;
  chunk.ref_count = n;
  return chunk;
}

template <class T>
void Grid<T>::set(Vec3i p, T value) {
  if (bounds_ && !bounds_->contains(p)) {
    throw InvalidArgument("set: voxel " + to_string(p) + " is outside the grid bounds " +
                          to_string(*bounds_));
  }
  if (!kCoordRange.contains(p)) {
    throw InvalidArgument("set: voxel " + to_string(p) +
                          " is outside the supported coordinate range " + to_string(kCoordRange));
  }
  const Vec3i coord = chunk_of(p);
  auto it = chunks_.find(coord);
  if (it == chunks_.end()) {
    if (value == background_) return;
    Chunk c;
    c.uniform = background_;
    it = chunks_.emplace(coord, std::move(c)).first;
  }
  Chunk& c = it->second;
  if (!c.voxels) {
    if (c.uniform == value) return;
    expand(c);
  }
  T& slot = c.voxels[local_index(p)];
  if (slot == value) return;
  if (slot == c.ref) --c.ref_count;
  if (value == c.ref) ++c.ref_count;
  VOXFIELD_ASSERT(c.ref_count >= 0 && c.ref_count <= chunk_volume());  // counts voxels equal to ref
  slot = value;
  // Every voxel is back to the value the chunk was expanded from: store it as that value again.
  if (c.ref_count == chunk_volume()) collapse_to_ref(it);
}

template <class T>
void Grid<T>::collapse_to_ref(typename ChunkMap::iterator it) {
  Chunk& c = it->second;
  if (c.ref == background_) {
    chunks_.erase(it);
  } else {
    c.voxels.reset();
    c.uniform = c.ref;
  }
}

template <class T>
void Grid<T>::reanchor(typename ChunkMap::iterator it, T value) {
  Chunk& c = it->second;
  const T* v = c.voxels.get();
  c.ref = value;
  c.ref_count = std::count(v, v + chunk_volume(), value);
  if (c.ref_count == chunk_volume()) collapse_to_ref(it);
}

template <class T>
void Grid<T>::collapse_if_uniform(typename ChunkMap::iterator it) {
  Chunk& c = it->second;
  if (!c.voxels) {
    if (c.uniform == background_) chunks_.erase(it);
    return;
  }
  const std::int64_t n = chunk_volume();
  const T first = c.voxels[0];
  const T* v = c.voxels.get();
  if (std::all_of(v, v + n, [&](const T& x) { return x == first; })) {
    if (first == background_) {
      chunks_.erase(it);
    } else {
      c.voxels.reset();
      c.uniform = first;
    }
    return;
  }
  // Still dense: re-anchor the O(1) collapse counter on the background, the most likely value
  // for edits to restore.
  c.ref = background_;
  c.ref_count = std::count(v, v + n, background_);
}

template <class T>
std::vector<Vec3i> Grid<T>::chunks_overlapping(const Box3i& box) const {
  std::vector<Vec3i> out;
  if (box.empty()) return out;
  const Vec3i lo = chunk_of(box.begin);
  const Vec3i hi = chunk_of(box.end - Vec3i::splat(1));
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) out.push_back({x, y, z});
  return out;
}

template <class T>
void Grid<T>::fill(const Box3i& box, T value) {
  if (box.empty()) return;
  require_in_bounds(box, "fill");
  for (const Vec3i coord : chunks_overlapping(box)) {
    const Box3i cb = chunk_box(coord);
    const Box3i part = cb.intersect(box);
    auto it = chunks_.find(coord);
    if (part == cb) {  // the whole chunk: store as a value
      if (value == background_) {
        if (it != chunks_.end()) chunks_.erase(it);
      } else {
        if (it == chunks_.end()) it = chunks_.emplace(coord, Chunk{}).first;
        it->second.voxels.reset();
        it->second.uniform = value;
      }
      continue;
    }
    if (it == chunks_.end()) {
      if (value == background_) continue;
      Chunk c;
      c.uniform = background_;
      it = chunks_.emplace(coord, std::move(c)).first;
    }
    Chunk& c = it->second;
    if (!c.voxels) {
      if (c.uniform == value) continue;
      expand(c);
    }
    // The collapse counter (voxels equal to c.ref) follows the writes: a fill costs its part of
    // the chunk, not the chunk (a .vdb's interior of 8^3 tiles fills a 32^3 chunk 64 times; a
    // scan of the chunk after each made that 30 % of reading the file). Only a chunk filled with
    // a value other than its reference is scanned, once, to anchor the counter on that value.
    const std::int64_t run = part.end.x - part.begin.x;
    for (int z = part.begin.z; z < part.end.z; ++z)
      for (int y = part.begin.y; y < part.end.y; ++y) {
        T* row = c.voxels.get() + local_index({part.begin.x, y, z});
        c.ref_count += (value == c.ref ? run : 0) - std::count(row, row + run, c.ref);
        std::fill(row, row + run, value);
      }
    if (c.ref_count == chunk_volume())
      collapse_to_ref(it);
    else if (!(value == c.ref))
      reanchor(it, value);
  }
}

template <class T>
void Grid<T>::copy_to_dense(const Box3i& box, T* out) const {
  if (box.empty()) return;
  if (!kCoordRange.contains(box)) {
    throw InvalidArgument("copy_to_dense: box " + to_string(box) +
                          " reaches outside the supported coordinate range " +
                          to_string(kCoordRange));
  }
  const Vec3i size = box.size();
  const std::int64_t sx = size.x, sxy = std::int64_t{size.x} * size.y;
  for (const Vec3i coord : chunks_overlapping(box)) {
    const Box3i part = chunk_box(coord).intersect(box);
    VOXFIELD_ASSERT(!part.empty());  // chunks_overlapping yields only chunks that meet the box
    auto it = chunks_.find(coord);
    const Chunk* c = it == chunks_.end() ? nullptr : &it->second;
    const int run = part.end.x - part.begin.x;
    for (int z = part.begin.z; z < part.end.z; ++z)
      for (int y = part.begin.y; y < part.end.y; ++y) {
        T* dst =
            out + (z - box.begin.z) * sxy + (y - box.begin.y) * sx + (part.begin.x - box.begin.x);
        if (c && c->voxels) {
          const T* src = c->voxels.get() + local_index({part.begin.x, y, z});
          std::copy(src, src + run, dst);
        } else {
          std::fill(dst, dst + run, c ? c->uniform : background_);
        }
      }
  }
}

template <class T>
void Grid<T>::copy_from_dense(const Box3i& box, const T* in) {
  if (box.empty()) return;
  require_in_bounds(box, "copy_from_dense");
  const Vec3i size = box.size();
  const std::int64_t sx = size.x, sxy = std::int64_t{size.x} * size.y;
  for (const Vec3i coord : chunks_overlapping(box)) {
    const Box3i part = chunk_box(coord).intersect(box);
    auto it = chunks_.find(coord);
    const int run = part.end.x - part.begin.x;
    auto row = [&](int y, int z) {
      return in + (z - box.begin.z) * sxy + (y - box.begin.y) * sx + (part.begin.x - box.begin.x);
    };
    if (it == chunks_.end() || !it->second.voxels) {
      // A uniform chunk (or an absent one, which holds the background) written with its own value
      // stays as it is: no expansion, no collapse scan — incremental field updates rewrite large
      // stretches of "clamp" in open air.
      const T uniform = it == chunks_.end() ? background_ : it->second.uniform;
      bool same = true;
      for (int z = part.begin.z; z < part.end.z && same; ++z)
        for (int y = part.begin.y; y < part.end.y && same; ++y) {
          const T* src = row(y, z);
          same = std::all_of(src, src + run, [&](const T& v) { return v == uniform; });
        }
      if (same) continue;
      if (it == chunks_.end()) {
        Chunk c;
        c.uniform = background_;
        it = chunks_.emplace(coord, std::move(c)).first;
      }
      expand(it->second);
    }
    Chunk& c = it->second;
    // The O(1) collapse counter (voxels equal to c.ref) follows the writes, so a chunk written
    // with varied values needs no scan of its own: it can only have become uniform at c.ref (the
    // counter says so) or, when everything written was one value, at that value (then scan).
    const T first = *row(part.begin.y, part.begin.z);
    bool written_uniform = true;
    for (int z = part.begin.z; z < part.end.z; ++z)
      for (int y = part.begin.y; y < part.end.y; ++y) {
        const T* src = row(y, z);
        T* dst = c.voxels.get() + local_index({part.begin.x, y, z});
        for (int x = 0; x < run; ++x) {
          written_uniform = written_uniform && src[x] == first;
          c.ref_count += (src[x] == c.ref ? 1 : 0) - (dst[x] == c.ref ? 1 : 0);
          dst[x] = src[x];
        }
      }
    if (c.ref_count == chunk_volume()) {
      collapse_to_ref(it);
    } else if (written_uniform && !(first == c.ref)) {
      reanchor(it, first);
    }
  }
}

template <class T>
Box3i Grid<T>::content_bounds() const {
  Box3i result{{0, 0, 0}, {0, 0, 0}};
  const int e = chunk_edge_;
  for (const auto& [coord, c] : chunks_) {
    const Box3i cb = chunk_box(coord);
    if (!c.voxels) {
      if (!(c.uniform == background_)) result = result.unite(cb);
      continue;
    }
    // Scan the dense chunk for its tight box; skip it when it cannot grow the result.
    if (result.contains(cb)) continue;
    Vec3i lo{e, e, e}, hi{-1, -1, -1};
    const T* v = c.voxels.get();
    for (int z = 0; z < e; ++z)
      for (int y = 0; y < e; ++y)
        for (int x = 0; x < e; ++x) {
          if (*v++ == background_) continue;
          lo = {std::min(lo.x, x), std::min(lo.y, y), std::min(lo.z, z)};
          hi = {std::max(hi.x, x), std::max(hi.y, y), std::max(hi.z, z)};
        }
    if (hi.x >= 0) result = result.unite(Box3i::from_inclusive(cb.begin + lo, cb.begin + hi));
  }
  return result;
}

template <class T>
std::int64_t Grid<T>::count_non_background() const {
  std::int64_t total = 0;
  const std::int64_t n = chunk_volume();
  for (const auto& [coord, c] : chunks_) {
    if (!c.voxels) {
      if (!(c.uniform == background_)) total += n;
    } else {
      total += n - std::count(c.voxels.get(), c.voxels.get() + n, background_);
    }
  }
  return total;
}

template <class T>
GridMemory Grid<T>::memory() const {
  GridMemory m;
  // Node-based hash map: one node (key, chunk, next pointer, cached hash) per chunk, plus the
  // bucket array.
  constexpr std::size_t kNodeBytes = sizeof(Vec3i) + sizeof(Chunk) + 2 * sizeof(void*);
  m.bytes = sizeof(Grid) + chunks_.bucket_count() * sizeof(void*) + chunks_.size() * kNodeBytes;
  for (const auto& [coord, c] : chunks_) {
    if (c.voxels) {
      ++m.dense_chunks;
      m.bytes += static_cast<std::size_t>(chunk_volume()) * sizeof(T);
    } else {
      ++m.uniform_chunks;
    }
  }
  m.voxels_covered = static_cast<std::int64_t>(chunks_.size()) * chunk_volume();
  return m;
}

template <class T>
void Grid<T>::compact() {
  for (auto it = chunks_.begin(); it != chunks_.end();) {
    auto next = std::next(it);
    collapse_if_uniform(it);
    it = next;
  }
}

template <class T>
void Grid<T>::for_each_chunk(const std::function<void(const ChunkView<T>&)>& f) const {
  for (const auto& [coord, c] : chunks_)
    f(ChunkView<T>{coord, chunk_box(coord), c.voxels.get(), c.uniform});
}

template <class T>
void Grid<T>::parallel_for_each_chunk(const std::function<void(const ChunkView<T>&)>& f) const {
  std::vector<const typename ChunkMap::value_type*> entries;
  entries.reserve(chunks_.size());
  for (const auto& entry : chunks_) entries.push_back(&entry);
  parallel_for(entries.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const auto& [coord, c] = *entries[i];
      f(ChunkView<T>{coord, chunk_box(coord), c.voxels.get(), c.uniform});
    }
  });
}

template <class T>
std::vector<Vec3i> Grid<T>::chunk_coords() const {
  std::vector<Vec3i> out;
  out.reserve(chunks_.size());
  for (const auto& entry : chunks_) out.push_back(entry.first);
  std::sort(out.begin(), out.end(), [](const Vec3i& a, const Vec3i& b) {
    return std::tie(a.z, a.y, a.x) < std::tie(b.z, b.y, b.x);
  });
  return out;
}

template <class T>
void Grid<T>::generate_chunks(const std::vector<Vec3i>& chunks,
                              const std::function<void(Vec3i, T*)>& f) {
  for (const Vec3i c : chunks) require_chunk_in_range(c, "generate_chunks");
  const std::int64_t n = chunk_volume();
  // Produce every chunk into fresh storage first, so that a throwing f leaves the grid unchanged.
  std::vector<ChunkArray<T>> produced(chunks.size());
  for (auto& p : produced) p = make_chunk_array<T>(static_cast<std::size_t>(n));
  parallel_for(chunks.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) f(chunks[i], produced[i].get());
  });
  adopt_chunks(chunks, std::move(produced));
}

template <class T>
void Grid<T>::adopt_chunks(const std::vector<Vec3i>& chunks, std::vector<ChunkArray<T>> data) {
  if (data.size() != chunks.size()) {
    throw InvalidArgument("adopt_chunks: " + std::to_string(data.size()) + " arrays for " +
                          std::to_string(chunks.size()) + " chunks");
  }
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    if (!data[i])
      throw InvalidArgument("adopt_chunks: null array for chunk " + to_string(chunks[i]));
    if (data[i].get_deleter().bytes != static_cast<std::size_t>(chunk_volume()) * sizeof(T)) {
      throw InvalidArgument("adopt_chunks: the array for chunk " + to_string(chunks[i]) +
                            " holds " + std::to_string(data[i].get_deleter().bytes) +
                            " bytes, not " +
                            std::to_string(chunk_volume() * std::int64_t{sizeof(T)}));
    }
    require_chunk_in_range(chunks[i], "adopt_chunks");
    if (bounds_ && chunk_box(chunks[i]).intersect(*bounds_).empty()) {
      throw InvalidArgument("adopt_chunks: chunk " + to_string(chunks[i]) +
                            " lies outside the grid bounds " + to_string(*bounds_));
    }
  }
  const std::int64_t n = chunk_volume();
  // The uniformity scan and the bounds reset run in parallel; only the map updates are sequential.
  std::vector<std::int64_t> background_count(chunks.size());
  std::vector<char> uniform(chunks.size());
  parallel_for(chunks.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      T* v = data[i].get();
      if (bounds_) {
        const Box3i cb = chunk_box(chunks[i]);
        if (!bounds_->contains(cb)) {
          // Voxels beyond the bounds do not exist: keep them at the background.
          for (int z = 0; z < chunk_edge_; ++z)
            for (int y = 0; y < chunk_edge_; ++y)
              for (int x = 0; x < chunk_edge_; ++x)
                if (!bounds_->contains(cb.begin + Vec3i{x, y, z}))
                  v[local_index({x, y, z})] = background_;
        }
      }
      const T first = v[0];
      uniform[i] = std::all_of(v, v + n, [&](const T& x) { return x == first; });
      background_count[i] =
          uniform[i] ? (first == background_ ? n : 0) : std::count(v, v + n, background_);
    }
  });
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    auto it = chunks_.find(chunks[i]);
    if (uniform[i] && data[i][0] == background_) {
      if (it != chunks_.end()) chunks_.erase(it);
      continue;
    }
    if (it == chunks_.end()) it = chunks_.emplace(chunks[i], Chunk{}).first;
    Chunk& c = it->second;
    if (uniform[i]) {
      c.uniform = data[i][0];
      c.voxels.reset();
    } else {
      c.voxels = std::move(data[i]);
      c.ref = background_;
      c.ref_count = background_count[i];
    }
  }
}

template <class T>
template <class F>
void Grid<T>::edit_chunk(Vec3i coord, F&& f) {
  require_chunk_in_range(coord, "edit_chunk");
  if (bounds_ && chunk_box(coord).intersect(*bounds_).empty()) {
    throw InvalidArgument("edit_chunk: chunk " + to_string(coord) +
                          " lies outside the grid bounds " + to_string(*bounds_));
  }
  auto it = chunks_.find(coord);
  if (it == chunks_.end()) {
    Chunk c;
    c.uniform = background_;
    it = chunks_.emplace(coord, std::move(c)).first;
  }
  Chunk& c = it->second;
  if (!c.voxels) expand(c);
  ChunkEdit edit(c.voxels.get(), c.ref, c.ref_count);
  try {
    f(edit);
  } catch (...) {
    c.ref_count = edit.ref_count_;
    if (c.ref_count == chunk_volume()) collapse_to_ref(it);
    throw;
  }
  c.ref_count = edit.ref_count_;
  if (c.ref_count == chunk_volume()) {
    collapse_to_ref(it);  // back to the value it was expanded from (an untouched expansion too)
  } else if (edit.writes_ > 0 && edit.one_value_ && !(edit.first_ == c.ref)) {
    // Only uniform at the value written, if at all: a check that stops at the first other voxel
    // (a count to re-anchor the counter would read the whole chunk on every small edit).
    const T* v = c.voxels.get();
    if (std::all_of(v, v + chunk_volume(), [&](const T& x) { return x == edit.first_; }))
      reanchor(it, edit.first_);
  }
}

template <class T>
void Grid<T>::require_chunk_in_range(Vec3i coord, const char* what) const {
  if (!chunk_in_range(coord)) {
    throw InvalidArgument(std::string(what) + ": chunk " + to_string(coord) + " of edge " +
                          std::to_string(chunk_edge_) +
                          " lies outside the supported coordinate range " + to_string(kCoordRange));
  }
}

template <class T>
Grid<T> Grid<T>::rechunked(int chunk_edge, std::optional<Box3i> bounds) const {
  Grid out(chunk_edge, background_, bounds);
  // Chunk by chunk, so that memory follows the content: uniform chunks become uniform fills (no
  // allocation where the new chunks lie wholly inside), dense ones are copied as they are.
  std::vector<T> part;
  for (const Vec3i coord : chunk_coords()) {
    const ChunkView<T> v = chunk_view(coord);
    Box3i box = bounds_ ? v.box.intersect(*bounds_) : v.box;
    if (bounds) box = box.intersect(*bounds);
    if (box.empty()) continue;
    if (v.uniform()) {
      out.fill(box, v.uniform_value);
    } else if (box == v.box) {
      out.copy_from_dense(box, v.voxels);
    } else {
      part.resize(static_cast<std::size_t>(box.volume()));
      copy_to_dense(box, part.data());
      out.copy_from_dense(box, part.data());
    }
  }
  return out;
}

template <class T>
T Grid<T>::ReadAccessor::get(Vec3i p) {
  const Vec3i coord = grid_->chunk_of(p);
  if (!(coord == cached_coord_)) {
    auto it = grid_->chunks_.find(coord);
    cached_chunk_ = it == grid_->chunks_.end() ? nullptr : &it->second;
    cached_coord_ = coord;
  }
  if (!cached_chunk_) return grid_->background_;
  const Chunk* c = static_cast<const Chunk*>(cached_chunk_);
  return c->voxels ? c->voxels[grid_->local_index(p)] : c->uniform;
}

}  // namespace voxfield
