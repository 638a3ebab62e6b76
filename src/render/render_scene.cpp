// voxfield renderer — preparing a world for rendering: the skip and lighting fields, the flat
// chunk table, empty-chunk flags and the linear-light palette.
#include <chrono>
#include <cstdlib>
#include <new>
#if defined(__linux__)
#include <sys/mman.h>
#endif
#include <algorithm>
#include <cmath>

#include "scene_impl.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"

namespace voxfield {
namespace render_detail {

LargeBuffer::LargeBuffer(std::size_t bytes) : size_(bytes) {
  if (bytes == 0) return;
  constexpr std::size_t kHuge = std::size_t{2} << 20;
  const std::size_t rounded = (bytes + kHuge - 1) / kHuge * kHuge;
  data_ = static_cast<std::uint8_t*>(std::aligned_alloc(kHuge, rounded));
  if (!data_) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  madvise(data_, rounded, MADV_HUGEPAGE);  // advice only: failure leaves normal pages
#endif
}

LargeBuffer::~LargeBuffer() { std::free(data_); }

ChunkTable::ChunkTable(const Box3i& box, int chunk_edge) : box_(box), edge_(chunk_edge) {
  while ((1 << shift_) < edge_) ++shift_;
  const Vec3i last{(box.end.x - 1) >> shift_, (box.end.y - 1) >> shift_, (box.end.z - 1) >> shift_};
  first_ = {box.begin.x >> shift_, box.begin.y >> shift_, box.begin.z >> shift_};
  dims_ = last - first_ + Vec3i::splat(1);
}

}  // namespace render_detail

namespace {

float srgb_to_linear(std::uint8_t c) {
  const double v = c / 255.0;
  return static_cast<float>(v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4));
}

}  // namespace

DistanceOptions skip_field_options(Metric metric, const Box3i& box) {
  DistanceOptions o;
  o.metric = metric;
  o.storage = Storage::kU8;
  o.max_distance = metric == Metric::kEuclidean ? 63 : 255;
  o.domain = box;
  return o;
}

namespace {

// Copies a u8 grid (and optionally a second one into the high byte) into bricked chunks.
template <class T>
BrickedChunks<T> brick(const render_detail::ChunkTable& table, const Grid<std::uint8_t>& low,
                       const Grid<std::uint8_t>* high) {
  BrickedChunks<T> out;
  const std::size_t n = table.chunk_count();
  out.chunk_volume = static_cast<std::uint32_t>(low.chunk_volume());
  out.slot.assign(n, BrickedChunks<T>::kUniform);
  out.uniform.assign(n, 0);
  std::uint32_t stored = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3i coord = table.chunk_coord(i);
    const ChunkView<std::uint8_t> l = low.chunk_view(coord);
    const ChunkView<std::uint8_t> h = high ? high->chunk_view(coord) : ChunkView<std::uint8_t>{coord, {}, nullptr, 0};
    if (l.voxels || h.voxels) {
      out.slot[i] = stored++;
    } else {
      out.uniform[i] = static_cast<T>(l.uniform_value | (h.uniform_value << 8));
    }
  }
  out.arena = render_detail::LargeBuffer(static_cast<std::size_t>(stored) * out.chunk_volume * sizeof(T));
  const int edge = low.chunk_edge();
  parallel_for(n, 4, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (out.slot[i] == BrickedChunks<T>::kUniform) continue;
      const Vec3i coord = table.chunk_coord(i);
      const ChunkView<std::uint8_t> l = low.chunk_view(coord);
      const ChunkView<std::uint8_t> h = high ? high->chunk_view(coord) : ChunkView<std::uint8_t>{coord, {}, nullptr, 0};
      T* dst = reinterpret_cast<T*>(out.arena.data()) + static_cast<std::size_t>(out.slot[i]) * out.chunk_volume;
      const Vec3i origin{coord.x * edge, coord.y * edge, coord.z * edge};
      std::size_t k = 0;
      for (int z = 0; z < edge; ++z)
        for (int y = 0; y < edge; ++y)
          for (int x = 0; x < edge; ++x, ++k) {
            const unsigned lo = l.voxels ? l.voxels[k] : l.uniform_value;
            const unsigned hi = h.voxels ? h.voxels[k] : h.uniform_value;
            dst[table.brick_index(origin + Vec3i{x, y, z})] = static_cast<T>(lo | (hi << 8));
          }
    }
  });
  return out;
}

void require_field(const DistanceField& f, const Box3i& box, int chunk_edge, const char* what) {
  if (f.options.storage != Storage::kU8 || f.options.signed_distance)
    throw InvalidArgument(std::string("render: the ") + what + " field must be unsigned with u8 storage");
  if (!f.domain.contains(box))
    throw InvalidArgument(std::string("render: the ") + what + " field's domain " + to_string(f.domain) +
                          " does not cover the render box " + to_string(box));
  if (f.chunk_edge() != chunk_edge)
    throw InvalidArgument(std::string("render: the ") + what + " field's chunk edge differs from the world's");
}

}  // namespace

SkipSource RenderScene::Impl::make_skip_source(const DistanceField& field) const {
  SkipSource src;
  src.metric = field.options.metric;
  src.inv_scale = 1.0 / field.encoding.scale;
  const auto& grid = std::get<Grid<std::uint8_t>>(field.values);
  src.cells = brick<std::uint16_t>(table, grid, &world->voxels);
  const std::size_t n = table.chunk_count();
  src.chunk_min.assign(n, 0);
  parallel_for(n, 4, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const ChunkView<std::uint8_t> v = grid.chunk_view(table.chunk_coord(i));
      std::uint8_t lowest = v.voxels ? 255 : v.uniform_value;
      if (v.voxels)
        for (std::uint32_t k = 0; k < src.cells.chunk_volume; ++k) lowest = std::min(lowest, v.voxels[k]);
      src.chunk_min[i] = lowest;
    }
  });
  return src;
}

void RenderScene::Impl::build(const World& w, const DistanceField& skip_field, const DistanceField* light_field) {
  const int edge = w.voxels.chunk_edge();
  require_field(skip_field, box, edge, "skip");
  if (light_field) {
    require_field(*light_field, box, edge, "lighting");
    if (light_field->options.metric != Metric::kEuclidean)
      throw InvalidArgument("render: the lighting field must be Euclidean");
  }
  table = render_detail::ChunkTable(box, edge);
  skip = make_skip_source(skip_field);
  has_light = light_field != nullptr;
  if (light_field) {
    light = brick<std::uint8_t>(table, std::get<Grid<std::uint8_t>>(light_field->values), nullptr);
    light_inv_scale = 1.0 / light_field->encoding.scale;
  }
  const std::size_t n = table.chunk_count();
  empty_chunk.assign(n, 0);
  dense_material.assign(n, 0);
  const std::size_t volume = static_cast<std::size_t>(w.voxels.chunk_volume());
  parallel_for(n, 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const ChunkView<std::uint8_t> v = w.voxels.chunk_view(table.chunk_coord(i));
      bool empty = true;
      if (v.voxels) {
        for (std::size_t k = 0; k < volume && empty; ++k) empty = v.voxels[k] == 0;
      } else {
        empty = v.uniform_value == 0;
      }
      empty_chunk[i] = empty ? 1 : 0;
      dense_material[i] = v.voxels ? 1 : 0;
    }
  });
  for (int m = 0; m < 256; ++m)
    albedo[m] = {srgb_to_linear(w.palette[m].r), srgb_to_linear(w.palette[m].g), srgb_to_linear(w.palette[m].b)};
}

namespace {

Box3i default_box(const World& world, std::optional<Box3i> box) {
  const Box3i b = box ? *box : world.voxels.bounds() ? *world.voxels.bounds() : world.voxels.content_bounds();
  if (b.empty()) throw InvalidArgument("render: nothing to render (empty box " + to_string(b) + ")");
  return b;
}

}  // namespace

RenderScene::RenderScene(const World& world, const RenderSceneOptions& options, std::optional<Box3i> box)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.world = &world;
  s.options = options;
  s.box = default_box(world, box);
  if (options.lighting_field && !(options.lighting_clamp > 0 && options.lighting_clamp <= 63))
    throw InvalidArgument("render: lighting clamp must lie in (0, 63] voxels");
  const auto t0 = std::chrono::steady_clock::now();
  const DistanceField skip = compute_distance_field(world, skip_field_options(options.skip_metric, s.box));
  std::optional<DistanceField> light;
  if (options.lighting_field) {
    DistanceOptions lo;
    lo.metric = Metric::kEuclidean;
    lo.storage = Storage::kU8;
    lo.max_distance = options.lighting_clamp;
    lo.domain = s.box;
    light = compute_distance_field(world, lo);
  }
  s.field_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  s.build(world, skip, light ? &*light : nullptr);
}

RenderScene::RenderScene(const World& world, const DistanceField& skip, const DistanceField* light,
                         std::optional<Box3i> box)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.world = &world;
  s.box = default_box(world, box);
  s.options.skip_metric = skip.options.metric;
  s.options.lighting_field = light != nullptr;
  if (light) s.options.lighting_clamp = light->options.max_distance;
  s.build(world, skip, light);
}

RenderScene::~RenderScene() = default;
RenderScene::RenderScene(RenderScene&&) noexcept = default;
RenderScene& RenderScene::operator=(RenderScene&&) noexcept = default;

const World& RenderScene::world() const { return *impl_->world; }
const Box3i& RenderScene::box() const { return impl_->box; }
const RenderSceneOptions& RenderScene::options() const { return impl_->options; }
double RenderScene::field_ms() const { return impl_->field_ms; }

}  // namespace voxfield
