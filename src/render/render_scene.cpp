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

VoxelLayer ChunkTable::layer(const Grid<std::uint8_t>& grid) const {
  VoxelLayer l;
  l.dense.resize(chunk_count(), nullptr);
  l.uniform.resize(chunk_count(), grid.background());
  for (std::size_t i = 0; i < chunk_count(); ++i) {
    const ChunkView<std::uint8_t> view = grid.chunk_view(chunk_coord(i));
    l.dense[i] = view.voxels;
    l.uniform[i] = view.uniform_value;
  }
  return l;
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

SkipSource RenderScene::Impl::make_skip_source(const DistanceField& field) const {
  SkipSource src;
  src.metric = field.options.metric;
  src.inv_scale = 1.0 / field.encoding.scale;
  const auto& grid = std::get<Grid<std::uint8_t>>(field.values);
  const Grid<std::uint8_t>& materials = world->voxels;
  const std::size_t n = table.chunk_count();
  src.chunk_volume = static_cast<std::uint32_t>(grid.chunk_volume());
  src.slot.assign(n, SkipSource::kUniform);
  src.chunk_min.assign(n, grid.background());
  src.chunk_material.assign(n, 0);
  std::uint32_t stored = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const ChunkView<std::uint8_t> d = grid.chunk_view(table.chunk_coord(i));
    const ChunkView<std::uint8_t> m = materials.chunk_view(table.chunk_coord(i));
    if (d.voxels || m.voxels) {
      src.slot[i] = stored++;
    } else {
      src.chunk_min[i] = d.uniform_value;
      src.chunk_material[i] = m.uniform_value;
    }
  }
  src.arena = render_detail::LargeBuffer(static_cast<std::size_t>(stored) * src.chunk_volume * 2);
  const int edge = grid.chunk_edge();
  parallel_for(n, 4, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (src.slot[i] == SkipSource::kUniform) continue;
      const Vec3i coord = table.chunk_coord(i);
      const ChunkView<std::uint8_t> d = grid.chunk_view(coord);
      const ChunkView<std::uint8_t> m = materials.chunk_view(coord);
      auto* out = reinterpret_cast<std::uint16_t*>(src.arena.data()) + static_cast<std::size_t>(src.slot[i]) * src.chunk_volume;
      std::uint8_t lowest = 255;
      const Vec3i origin{coord.x * edge, coord.y * edge, coord.z * edge};
      std::size_t k = 0;
      for (int z = 0; z < edge; ++z)
        for (int y = 0; y < edge; ++y)
          for (int x = 0; x < edge; ++x, ++k) {
            const std::uint8_t distance = d.voxels ? d.voxels[k] : d.uniform_value;
            const std::uint8_t material = m.voxels ? m.voxels[k] : m.uniform_value;
            out[table.brick_index(origin + Vec3i{x, y, z})] = static_cast<std::uint16_t>(distance | (material << 8));
            lowest = std::min(lowest, distance);
          }
      src.chunk_min[i] = lowest;
    }
  });
  return src;
}

RenderScene::RenderScene(const World& world, const RenderSceneOptions& options, std::optional<Box3i> box)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.world = &world;
  s.options = options;
  s.box = box ? *box : world.voxels.bounds() ? *world.voxels.bounds() : world.voxels.content_bounds();
  if (s.box.empty()) throw InvalidArgument("render: nothing to render (empty box " + to_string(s.box) + ")");
  if (options.lighting_field && !(options.lighting_clamp > 0 && options.lighting_clamp <= 63))
    throw InvalidArgument("render: lighting clamp must lie in (0, 63] voxels");

  const auto t0 = std::chrono::steady_clock::now();
  s.skip_field = compute_distance_field(world, skip_field_options(options.skip_metric, s.box));
  if (options.lighting_field) {
    DistanceOptions lo;
    lo.metric = Metric::kEuclidean;
    lo.storage = Storage::kU8;
    lo.max_distance = options.lighting_clamp;
    lo.domain = s.box;
    s.light_field = compute_distance_field(world, lo);
  }
  s.field_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  s.table = render_detail::ChunkTable(s.box, world.voxels.chunk_edge());
  s.material = s.table.layer(world.voxels);
  s.skip = s.make_skip_source(s.skip_field);
  if (s.light_field) {
    s.light = s.table.layer(std::get<Grid<std::uint8_t>>(s.light_field->values));
    s.light_inv_scale = 1.0 / s.light_field->encoding.scale;
  }
  s.empty_chunk.assign(s.table.chunk_count(), 0);
  const std::size_t volume = static_cast<std::size_t>(world.voxels.chunk_volume());
  parallel_for(s.table.chunk_count(), 16, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const std::uint8_t* d = s.material.dense[i];
      bool empty = true;
      if (d) {
        for (std::size_t k = 0; k < volume && empty; ++k) empty = d[k] == 0;
      } else {
        empty = s.material.uniform[i] == 0;
      }
      s.empty_chunk[i] = empty ? 1 : 0;
    }
  });
  for (int m = 0; m < 256; ++m)
    s.albedo[m] = {srgb_to_linear(world.palette[m].r), srgb_to_linear(world.palette[m].g),
                   srgb_to_linear(world.palette[m].b)};
}

RenderScene::~RenderScene() = default;
RenderScene::RenderScene(RenderScene&&) noexcept = default;
RenderScene& RenderScene::operator=(RenderScene&&) noexcept = default;

const World& RenderScene::world() const { return *impl_->world; }
const Box3i& RenderScene::box() const { return impl_->box; }
const RenderSceneOptions& RenderScene::options() const { return impl_->options; }
const DistanceField& RenderScene::skip_field() const { return impl_->skip_field; }
double RenderScene::field_ms() const { return impl_->field_ms; }

}  // namespace voxfield
