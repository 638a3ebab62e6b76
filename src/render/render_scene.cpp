// voxfield renderer — preparing a world for rendering: the skip and lighting fields, the flat
// chunk table, empty-chunk flags and the linear-light palette.
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#include <algorithm>
#include <cmath>

#include "scene_impl.h"
#include "shading.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"

namespace voxfield {

template <class T>
std::uint32_t BrickedChunks<T>::take_slot() {
  if (!free_slots.empty()) {
    const std::uint32_t s = free_slots.back();
    free_slots.pop_back();
    return s;
  }
  const std::size_t needed = (std::size_t{slots_used} + 1) * slot_bytes();
  if (needed > arena.size()) {
    // Grow by half again, so a stream of edits that densify chunks costs amortised O(1) copies.
    const std::size_t slots =
        std::max<std::size_t>(std::size_t{slots_used} + 1, std::size_t{slots_used} * 3 / 2 + 4);
    render_detail::LargeBuffer bigger(slots * slot_bytes());
    if (slots_used > 0)
      std::memcpy(bigger.data(), arena.data(), std::size_t{slots_used} * slot_bytes());
    arena = std::move(bigger);
  }
  return slots_used++;
}

namespace render_detail {

LargeBuffer::LargeBuffer(std::size_t bytes) : size_(bytes) {
  if (bytes == 0) return;
  constexpr std::size_t kHuge = std::size_t{2} << 20;
  const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
#if defined(__linux__)
  // Anonymous pages arrive zeroed and only when touched, so a buffer grown for a few more chunks
  // costs nothing until they are written; over-map by 2 MiB to align the start to a huge page.
  void* p =
      mmap(nullptr, rounded + kHuge, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) throw std::bad_alloc();
  map_ = p;
  map_bytes_ = rounded + kHuge;
  const auto addr = reinterpret_cast<std::uintptr_t>(p);
  data_ = reinterpret_cast<std::uint8_t*>((addr + kHuge - 1) / kHuge * kHuge);
#ifdef MADV_HUGEPAGE
  madvise(data_, rounded, MADV_HUGEPAGE);  // advice only: failure leaves normal pages
#endif
#else
  data_ = static_cast<std::uint8_t*>(std::aligned_alloc(kHuge, rounded));
  if (!data_) throw std::bad_alloc();
  std::memset(data_, 0, rounded);
#endif
}

LargeBuffer::~LargeBuffer() {
#if defined(__linux__)
  if (map_) munmap(map_, map_bytes_);
#else
  std::free(data_);
#endif
}

ChunkTable::ChunkTable(const Box3i& box, int chunk_edge) : box_(box), edge_(chunk_edge) {
  while ((1 << shift_) < edge_) ++shift_;
  const Vec3i last{(box.end.x - 1) >> shift_, (box.end.y - 1) >> shift_, (box.end.z - 1) >> shift_};
  first_ = {box.begin.x >> shift_, box.begin.y >> shift_, box.begin.z >> shift_};
  dims_ = last - first_ + Vec3i::splat(1);
}

std::vector<std::size_t> ChunkTable::chunks_touching(std::span<const Box3i> boxes) const {
  std::vector<std::size_t> chunks;
  for (const Box3i& b : boxes) {
    const Box3i clipped = b.intersect(box_);
    if (clipped.empty()) continue;
    for (int cz = clipped.begin.z >> shift_; cz <= (clipped.end.z - 1) >> shift_; ++cz)
      for (int cy = clipped.begin.y >> shift_; cy <= (clipped.end.y - 1) >> shift_; ++cy)
        for (int cx = clipped.begin.x >> shift_; cx <= (clipped.end.x - 1) >> shift_; ++cx)
          chunks.push_back(chunk_index(Vec3i{cx << shift_, cy << shift_, cz << shift_}));
  }
  std::sort(chunks.begin(), chunks.end());
  chunks.erase(std::unique(chunks.begin(), chunks.end()), chunks.end());
  return chunks;
}

}  // namespace render_detail

using render_detail::srgb_to_linear;

DistanceOptions skip_field_options(const RenderSceneOptions& options, const Box3i& box) {
  DistanceOptions o;
  o.metric = options.skip_metric;
  o.storage = Storage::kU8;
  const double most = o.metric == Metric::kEuclidean ? 63 : 255;
  if (!(options.skip_max_distance_vox >= 0 && options.skip_max_distance_vox <= most))
    throw InvalidArgument(
        "render: skip_max_distance_vox (the skip field's clamp) must lie in [0, " +
        std::to_string(static_cast<int>(most)) + "] voxels for the " + metric_name(o.metric) +
        " metric (0 = the most)");
  o.max_distance = options.skip_max_distance_vox > 0 ? options.skip_max_distance_vox : most;
  o.domain = box;
  return o;
}

DistanceOptions light_field_options(const RenderSceneOptions& options, const Box3i& box) {
  if (!(options.lighting_max_distance_vox > 0 && options.lighting_max_distance_vox <= 63))
    throw InvalidArgument(
        "render: lighting_max_distance_vox (the lighting field's clamp) must lie in (0, 63] "
        "voxels");
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.storage = Storage::kU8;
  o.max_distance = options.lighting_max_distance_vox;
  o.domain = box;
  return o;
}

void check_render_scene_options(const RenderSceneOptions& options) {
  (void)skip_field_options(options, {});
  if (options.lighting_field) (void)light_field_options(options, {});
}

namespace {

std::atomic<std::uint64_t> next_scene_id{1};

// Decides how chunk i of `out` is stored: in a slot when either source chunk is stored voxel by
// voxel (its voxels are then copied by copy_chunk), else as one value (its slot, if it had one,
// goes back to the free list). Returns whether that changed the chunk (a new slot, or another
// uniform value).
template <class T>
bool place_chunk(BrickedChunks<T>& out, const render_detail::ChunkTable& table, std::size_t i,
                 const Grid<std::uint8_t>& low, const Grid<std::uint8_t>* high) {
  const Vec3i coord = table.chunk_coord(i);
  const ChunkView<std::uint8_t> l = low.chunk_view(coord);
  const ChunkView<std::uint8_t> h =
      high ? high->chunk_view(coord) : ChunkView<std::uint8_t>{coord, {}, nullptr, 0};
  if (l.voxels || h.voxels) {
    if (out.slot[i] != BrickedChunks<T>::kUniform) return false;
    out.slot[i] = out.take_slot();
    return true;
  }
  const bool changed = out.slot[i] != BrickedChunks<T>::kUniform ||
                       out.uniform[i] != static_cast<T>(l.uniform_value | (h.uniform_value << 8));
  if (out.slot[i] != BrickedChunks<T>::kUniform) {
    out.free_slots.push_back(out.slot[i]);
    out.slot[i] = BrickedChunks<T>::kUniform;
  }
  out.uniform[i] = static_cast<T>(l.uniform_value | (h.uniform_value << 8));
  return changed;
}

// Copies chunk i of a u8 grid (and optionally a second one into the high byte) into its slot,
// bricked. Returns whether any value differs from what the slot held.
template <class T>
bool copy_chunk(BrickedChunks<T>& out, const render_detail::ChunkTable& table, std::size_t i,
                const Grid<std::uint8_t>& low, const Grid<std::uint8_t>* high) {
  const Vec3i coord = table.chunk_coord(i);
  const ChunkView<std::uint8_t> l = low.chunk_view(coord);
  const ChunkView<std::uint8_t> h =
      high ? high->chunk_view(coord) : ChunkView<std::uint8_t>{coord, {}, nullptr, 0};
  T* dst = out.slot_data(out.slot[i]);
  const int edge = low.chunk_edge();
  const Vec3i origin{coord.x * edge, coord.y * edge, coord.z * edge};
  std::size_t k = 0;
  bool changed = false;
  for (int z = 0; z < edge; ++z)
    for (int y = 0; y < edge; ++y)
      for (int x = 0; x < edge; ++x, ++k) {
        const unsigned lo = l.voxels ? l.voxels[k] : l.uniform_value;
        const unsigned hi = h.voxels ? h.voxels[k] : h.uniform_value;
        T& cell = dst[table.brick_index(origin + Vec3i{x, y, z})];
        const auto value = static_cast<T>(lo | (hi << 8));
        changed = changed || cell != value;
        cell = value;
      }
  return changed;
}

// The smallest value of a chunk of a u8 grid.
std::uint8_t chunk_min(const Grid<std::uint8_t>& grid, Vec3i coord, std::uint32_t volume) {
  const ChunkView<std::uint8_t> d = grid.chunk_view(coord);
  if (!d.voxels) return d.uniform_value;
  std::uint8_t lowest = 255;
  for (std::uint32_t k = 0; k < volume; ++k) lowest = std::min(lowest, d.voxels[k]);
  return lowest;
}

// Empty bricked chunks for the table, with an arena sized for the chunks stored densely now.
template <class T>
BrickedChunks<T> empty_bricks(const render_detail::ChunkTable& table, const Grid<std::uint8_t>& low,
                              const Grid<std::uint8_t>* high) {
  BrickedChunks<T> out;
  const std::size_t n = table.chunk_count();
  out.chunk_volume = static_cast<std::uint32_t>(low.chunk_volume());
  out.slot.assign(n, BrickedChunks<T>::kUniform);
  out.uniform.assign(n, 0);
  std::size_t dense = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3i coord = table.chunk_coord(i);
    dense += low.chunk_view(coord).voxels || (high && high->chunk_view(coord).voxels) ? 1 : 0;
  }
  out.arena = render_detail::LargeBuffer(dense * out.slot_bytes());
  return out;
}

void require_field(const DistanceField& f, const Box3i& box, int chunk_edge, const char* what) {
  if (f.options.storage != Storage::kU8 || f.options.signed_distance)
    throw InvalidArgument(std::string("render: the ") + what +
                          " field must be unsigned with u8 storage");
  if (!f.domain.contains(box))
    throw InvalidArgument(std::string("render: the ") + what + " field's domain " +
                          to_string(f.domain) + " does not cover the render box " + to_string(box));
  if (f.chunk_edge() != chunk_edge)
    throw InvalidArgument(std::string("render: the ") + what +
                          " field's chunk edge differs from the world's");
}

}  // namespace

bool RenderScene::Impl::refresh_chunk(std::size_t i, const Grid<std::uint8_t>& skip_grid,
                                      const Grid<std::uint8_t>* light_grid) {
  const Vec3i coord = table.chunk_coord(i);
  bool changed = false;
  if (skip.cells.slot[i] != BrickedChunks<std::uint16_t>::kUniform)
    changed = copy_chunk(skip.cells, table, i, skip_grid, &world->voxels);
  if (light_grid && light.slot[i] != BrickedChunks<std::uint8_t>::kUniform)
    changed = copy_chunk(light, table, i, *light_grid, nullptr) || changed;
  const std::uint8_t old_min = skip.chunk_min[i], old_empty = empty_chunk[i],
                     old_dense = dense_material[i];
  skip.chunk_min[i] = chunk_min(skip_grid, coord, skip.cells.chunk_volume);
  const ChunkView<std::uint8_t> v = world->voxels.chunk_view(coord);
  bool empty = true;
  if (v.voxels) {
    for (std::uint32_t k = 0; k < skip.cells.chunk_volume && empty; ++k) empty = v.voxels[k] == 0;
  } else {
    empty = v.uniform_value == 0;
  }
  empty_chunk[i] = empty ? 1 : 0;
  dense_material[i] = v.voxels ? 1 : 0;
  return changed || old_min != skip.chunk_min[i] || old_empty != empty_chunk[i] ||
         old_dense != dense_material[i];
}

namespace {

// Linear-light albedo of a palette.
std::array<std::array<float, 3>, 256> linear_albedo(const World& w) {
  std::array<std::array<float, 3>, 256> out{};
  for (int m = 0; m < 256; ++m)
    out[m] = {srgb_to_linear(w.palette[m].r), srgb_to_linear(w.palette[m].g),
              srgb_to_linear(w.palette[m].b)};
  return out;
}

void check_fields(const RenderScene::Impl& s, const DistanceField& skip_field,
                  const DistanceField* light_field, int edge) {
  require_field(skip_field, s.box, edge, "skip");
  if (light_field) {
    require_field(*light_field, s.box, edge, "lighting");
    if (light_field->options.metric != Metric::kEuclidean)
      throw InvalidArgument("render: the lighting field must be Euclidean");
  }
}

}  // namespace

int RenderScene::Impl::slice_z(const RenderOptions& o) const {
  const int z = o.slice_z ? *o.slice_z : (box.begin.z + box.end.z) / 2;
  if (z < box.begin.z || z >= box.end.z)
    throw InvalidArgument("render: slice z=" + std::to_string(z) + " lies outside the box " +
                          to_string(box));
  return z;
}

std::uint32_t RenderScene::Impl::heat_top(int z) const {
  std::uint32_t top = 1;
  for (int y = box.begin.y; y < box.end.y; ++y)
    for (int x = box.begin.x; x < box.end.x; ++x) {
      const Vec3i v{x, y, z};
      top = std::max<std::uint32_t>(top, skip.distance(table.chunk_index(v), table.brick_index(v)));
    }
  return top;
}

double RenderScene::Impl::heat_max(int z) const {
  return std::max(1.0, heat_top(z) * skip.inv_scale);
}

SkipSource RenderScene::Impl::approximation(Algorithm algorithm) const {
  return render_detail::approximation(table, *world, skip_options, algorithm);
}

AlgorithmOptions RenderScene::Impl::approximation_options(Algorithm algorithm) const {
  return render_detail::approximation_options(box, algorithm);
}

SkipSource RenderScene::Impl::make_skip_source(const DistanceField& field) const {
  return render_detail::make_skip_source(table, *world, field);
}

namespace render_detail {

SkipSource approximation(const ChunkTable& table, const World& world,
                         const DistanceOptions& skip_options, Algorithm algorithm) {
  return make_skip_source(
      table, world,
      compute_distance_field(world, skip_options, approximation_options(table.box(), algorithm)));
}

AlgorithmOptions approximation_options(const Box3i& box, Algorithm algorithm) {
  AlgorithmOptions ao;
  ao.algorithm = algorithm;
  if (algorithm == Algorithm::kLod) {
    // FIM in the middle of the box (3/8 to 5/8 of each extent, as `voxfield compare` does).
    const Vec3i sz = box.size();
    const Vec3i lo{sz.x * 3 / 8, sz.y * 3 / 8, sz.z * 3 / 8};
    const Vec3i hi{std::max(sz.x * 5 / 8, lo.x + 1), std::max(sz.y * 5 / 8, lo.y + 1),
                   std::max(sz.z * 5 / 8, lo.z + 1)};
    ao.focus = Box3i{box.begin + lo, box.begin + hi};
  }
  return ao;
}

SkipSource make_skip_source(const ChunkTable& table, const World& world,
                            const DistanceField& field) {
  SkipSource src;
  src.metric = field.options.metric;
  src.inv_scale = 1.0 / field.encoding.scale;
  const auto& grid = std::get<Grid<std::uint8_t>>(field.values);
  src.cells = empty_bricks<std::uint16_t>(table, grid, &world.voxels);
  const std::size_t n = table.chunk_count();
  src.chunk_min.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) place_chunk(src.cells, table, i, grid, &world.voxels);
  parallel_for(n, 4, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (src.cells.slot[i] != BrickedChunks<std::uint16_t>::kUniform)
        copy_chunk(src.cells, table, i, grid, &world.voxels);
      src.chunk_min[i] = chunk_min(grid, table.chunk_coord(i), src.cells.chunk_volume);
    }
  });
  return src;
}

}  // namespace render_detail

void RenderScene::Impl::build(const World& w, const DistanceField& skip_field,
                              const DistanceField* light_field) {
  const int edge = w.voxels.chunk_edge();
  check_fields(*this, skip_field, light_field, edge);
  id = next_scene_id.fetch_add(1);
  table = render_detail::ChunkTable(box, edge);
  const auto& skip_grid = std::get<Grid<std::uint8_t>>(skip_field.values);
  const Grid<std::uint8_t>* light_grid =
      light_field ? &std::get<Grid<std::uint8_t>>(light_field->values) : nullptr;
  skip_options = skip_field.options;
  skip.metric = skip_field.options.metric;
  skip.inv_scale = 1.0 / skip_field.encoding.scale;
  skip.cells = empty_bricks<std::uint16_t>(table, skip_grid, &w.voxels);
  has_light = light_grid != nullptr;
  if (light_grid) {
    light = empty_bricks<std::uint8_t>(table, *light_grid, nullptr);
    light_inv_scale = 1.0 / light_field->encoding.scale;
  }
  const std::size_t n = table.chunk_count();
  skip.chunk_min.assign(n, 0);
  empty_chunk.assign(n, 0);
  dense_material.assign(n, 0);
  chunk_generation.assign(n, generation);
  for (std::size_t i = 0; i < n; ++i) {
    place_chunk(skip.cells, table, i, skip_grid, &w.voxels);
    if (light_grid) place_chunk(light, table, i, *light_grid, nullptr);
  }
  parallel_for(n, 4, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) refresh_chunk(i, skip_grid, light_grid);
  });
  palette = w.palette;
  albedo = linear_albedo(w);
}

std::size_t RenderScene::update(const DistanceField& skip_field, const DistanceField* light_field,
                                std::span<const Box3i> boxes) {
  Impl& s = *impl_;
  check_fields(s, skip_field, light_field, s.table.chunk_edge());
  if (skip_field.options.metric != s.skip.metric ||
      1.0 / skip_field.encoding.scale != s.skip.inv_scale)
    throw InvalidArgument("render: update() needs a skip field of the scene's metric and scale");
  if ((light_field != nullptr) != s.has_light ||
      (light_field && 1.0 / light_field->encoding.scale != s.light_inv_scale))
    throw InvalidArgument(
        "render: update() needs a lighting field exactly when the scene has one, of its scale");
  if (s.world->voxels.chunk_edge() != s.table.chunk_edge())
    throw InvalidArgument("render: the world's chunk edge changed since the scene was made");

  const std::vector<std::size_t> chunks = s.table.chunks_touching(boxes);
  if (chunks.empty()) return 0;

  const auto& skip_grid = std::get<Grid<std::uint8_t>>(skip_field.values);
  const Grid<std::uint8_t>* light_grid =
      light_field ? &std::get<Grid<std::uint8_t>>(light_field->values) : nullptr;
  // Slots change hands one chunk at a time; then the voxels are copied in parallel. Only chunks
  // whose contents really changed get a new generation (and are copied to a GPU again).
  std::vector<std::uint8_t> changed(chunks.size(), 0);
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    changed[k] = place_chunk(s.skip.cells, s.table, chunks[k], skip_grid, &s.world->voxels) ? 1 : 0;
    if (light_grid && place_chunk(s.light, s.table, chunks[k], *light_grid, nullptr))
      changed[k] = 1;
  }
  parallel_for(chunks.size(), 4, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k)
      if (s.refresh_chunk(chunks[k], skip_grid, light_grid)) changed[k] = 1;
  });
  ++s.generation;
  std::size_t count = 0;
  for (std::size_t k = 0; k < chunks.size(); ++k)
    if (changed[k]) {
      s.chunk_generation[chunks[k]] = s.generation;
      ++count;
    }
  if (s.world->palette != s.palette) {  // decoded only when it changed, not on every edit
    s.palette = s.world->palette;
    s.albedo = linear_albedo(*s.world);
    s.palette_generation = s.generation;
  }
  return count;
}

namespace {

Box3i default_box(const World& world, std::optional<Box3i> box) {
  const Box3i b = box                     ? *box
                  : world.voxels.bounds() ? *world.voxels.bounds()
                                          : world.voxels.content_bounds();
  if (b.empty())
    throw InvalidArgument("render: nothing to render (empty box " + to_string(b) + ")");
  return b;
}

}  // namespace

RenderScene::RenderScene(const World& world, const RenderSceneOptions& options,
                         std::optional<Box3i> box)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.world = &world;
  s.options = options;
  s.box = default_box(world, box);
  const DistanceOptions skip_o = skip_field_options(options, s.box);
  std::optional<DistanceOptions> light_o;
  if (options.lighting_field) light_o = light_field_options(options, s.box);
  const auto t0 = std::chrono::steady_clock::now();
  const DistanceField skip = compute_distance_field(world, skip_o);
  std::optional<DistanceField> light;
  if (light_o) light = compute_distance_field(world, *light_o);
  s.field_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  s.build(world, skip, light ? &*light : nullptr);
}

RenderScene::RenderScene(const World& world, const DistanceField& skip, const DistanceField* light,
                         std::optional<Box3i> box)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.world = &world;
  s.box = default_box(world, box);
  s.options.skip_metric = skip.options.metric;
  s.options.skip_max_distance_vox =
      std::isfinite(skip.options.max_distance) ? skip.options.max_distance : 0;
  s.options.lighting_field = light != nullptr;
  if (light) s.options.lighting_max_distance_vox = light->options.max_distance;
  s.build(world, skip, light);
}

RenderScene::~RenderScene() = default;
RenderScene::RenderScene(RenderScene&&) noexcept = default;
RenderScene& RenderScene::operator=(RenderScene&&) noexcept = default;

const World& RenderScene::world() const {
  return *impl_->world;
}
const Box3i& RenderScene::box() const {
  return impl_->box;
}
const RenderSceneOptions& RenderScene::options() const {
  return impl_->options;
}
double RenderScene::field_ms() const {
  return impl_->field_ms;
}

}  // namespace voxfield
