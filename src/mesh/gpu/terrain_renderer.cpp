// voxfield GPU backend — the terrain drawn from its HistoPyramid (gpu_terrain.h): the field
// resident in its own width, uploaded whole once and then row by row where edits changed it;
// per frame classify, the pyramid's levels and the draw's arguments in compute, then one indirect
// draw whose vertex shader walks the pyramid (mesh_draw.vert), every barrier derived by the
// recorder (graphics.h for the images').
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "gpu/graphics.h"
#include "gpu/recorder.h"
#include "histopyramid.h"
#include "mesh_shaders.h"
#include "shaders/layout.h"
#include "voxfield/error.h"
#include "voxfield/gpu_terrain.h"
#include "voxfield/gpu_terrain_vulkan.h"
#include "voxfield/limits.h"

namespace voxfield::gpu {

namespace L = layout;

namespace {

using mc::kUsage;

// The resident copy's shape: a terrain of another shape is copied whole.
struct Shape {
  Vec3i n;
  TerrainStorage storage = TerrainStorage::kI16;
  double step = 0;
  std::array<double, 3> origin{};
  double spacing = 0;
  bool palette = false;
  std::array<std::uint32_t, 256> colours{};
  bool operator==(const Shape&) const = default;
};

Shape shape_of(const TerrainField& terrain) {
  const TerrainOptions& o = terrain.options();
  Shape s;
  s.n = o.samples;
  s.storage = o.storage;
  s.step = terrain.step_units();
  s.origin = o.origin_units;
  s.spacing = o.spacing_units;
  s.palette = o.palette.has_value();
  if (o.palette)
    for (std::size_t m = 0; m < 256; ++m) {
      const Rgba c = (*o.palette)[m];
      s.colours[m] = static_cast<std::uint32_t>(c.r) | static_cast<std::uint32_t>(c.g) << 8 |
                     static_cast<std::uint32_t>(c.b) << 16 | 0xff000000u;
    }
  return s;
}

L::vec4f v4(const Vec3d& v, double w = 0) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
          static_cast<float>(w)};
}

std::uint64_t rounded4(std::uint64_t bytes) {
  return std::max<std::uint64_t>(4, (bytes + 3) / 4 * 4);
}

}  // namespace

struct TerrainRenderer::Impl {
  std::shared_ptr<Context> context;
  Context::Impl& c;
  Pyramid pyramid_kind;
  bool synced = false;
  Shape shape;
  int bytes = 2;  // per sample
  Vec3i cells;
  std::vector<L::ivec4> levels;
  Buffer samples, materials, tables, frame, level_buf, pyramid, cases, view, palette, draw;
  std::unique_ptr<RenderTarget> target;
  std::unique_ptr<GraphicsKernel> graphics;
  Buffer pixels;  // record_render's frame, read by the application's copy
  DescriptorArena sets;

  Impl(std::shared_ptr<Context> ctx, Pyramid kind)
      : context(std::move(ctx)), c(context->impl()), pyramid_kind(kind), sets(c) {}

  std::uint64_t upload_whole(const TerrainField& terrain);
  std::uint64_t upload_rows(const TerrainField& terrain, std::span<const Box3i> boxes);
  void ensure_target(int width, int height, VkFormat format);
  L::MeshParams params() const;
  void record_frame(Recorder& rec, const TerrainView& o);
};

std::uint64_t TerrainRenderer::Impl::upload_whole(const TerrainField& terrain) {
  const Shape next = shape_of(terrain);
  mc::check_lattice(next.n, next.origin, {next.spacing, next.spacing, next.spacing});
  const Vec3i n = next.n;
  const std::uint64_t count = static_cast<std::uint64_t>(n.x) * n.y * n.z;
  const int width = terrain.options().storage == TerrainStorage::kI8    ? 1
                    : terrain.options().storage == TerrainStorage::kI16 ? 2
                                                                        : 4;
  const Vec3i cell_dims{n.x - 1, n.y - 1, n.z - 1};
  std::uint64_t pyramid_elements = 0;
  std::vector<L::ivec4> next_levels = mc::pyramid_levels(cell_dims, pyramid_kind, pyramid_elements);
  const std::uint64_t cell_count =
      static_cast<std::uint64_t>(cell_dims.x) * cell_dims.y * cell_dims.z;
  const VkDeviceSize range = c.limits.maxStorageBufferRange;
  for (const auto& [what, b] :
       {std::pair<const char*, std::uint64_t>{"samples", count * static_cast<std::uint64_t>(width)},
        {"HistoPyramid", pyramid_elements * 4},
        {"cell cases", cell_count * 4}})
    if (b > range)
      throw ResourceLimitError("the GPU terrain renderer: the " + std::string(what) + " of " +
                               to_string(n) + " samples take " + std::to_string(b) +
                               " bytes, more than one storage buffer of " + c.info.name +
                               " holds (" + std::to_string(range) + ")");
  const std::uint64_t sample_bytes = rounded4(count * static_cast<std::uint64_t>(width));
  const std::uint64_t material_bytes = rounded4(count);
  require_memory(sample_bytes + material_bytes, 0, "the GPU terrain renderer",
                 "the upload of a " + to_string(n) + " terrain");
  // The buffers are replaced: frames recorded earlier must be done with the old ones first.
  if (synced) check(vkQueueWaitIdle(c.queue), "vkQueueWaitIdle");
  synced = false;  // until every buffer below is made and filled: a failure leaves no frame
  sets.reset();
  const std::vector<std::uint32_t> table = mc::case_table();
  const std::array<double, 8> frame_data{next.origin[0], next.origin[1], next.origin[2], next.step,
                                         next.spacing,   next.spacing,   next.spacing,   0};
  samples = Buffer(c, sample_bytes, kUsage, false);
  materials = Buffer(c, material_bytes, kUsage, false);
  tables = Buffer(c, table.size() * 4, kUsage, false);
  frame = Buffer(c, sizeof frame_data, kUsage, false);
  level_buf = Buffer(c, next_levels.size() * sizeof(L::ivec4), kUsage, false);
  pyramid = Buffer(c, pyramid_elements * 4, kUsage, false);
  cases = Buffer(c, cell_count * 4, kUsage, false);
  view = Buffer(c, sizeof(L::MeshDrawView), kUsage, false);
  palette = Buffer(c, 256 * 4, kUsage, false);
  draw = Buffer(c, 16, kUsage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, true);

  // One staging area: the codes and materials (read in the field's own width), then the tables.
  const std::uint64_t parts[6] = {sample_bytes,
                                  material_bytes,
                                  table.size() * 4,
                                  sizeof frame_data,
                                  next_levels.size() * sizeof(L::ivec4),
                                  256 * 4};
  std::uint64_t total = 0;
  for (std::uint64_t b : parts) total += (b + 15) / 16 * 16;
  Buffer& staging = c.upload_buffer(total);
  auto* base = static_cast<std::uint8_t*>(staging.mapped());
  std::uint64_t offsets[6];
  for (std::uint64_t i = 0, at = 0; i < 6; at += (parts[i] + 15) / 16 * 16, ++i) offsets[i] = at;
  std::memset(base + offsets[0], 0, sample_bytes);  // the padding past the last sample
  std::memset(base + offsets[1], 0, material_bytes);
  terrain.read_codes(Box3i::from_size(n), base + offsets[0], base + offsets[1]);
  std::memcpy(base + offsets[2], table.data(), parts[2]);
  std::memcpy(base + offsets[3], frame_data.data(), parts[3]);
  std::memcpy(base + offsets[4], next_levels.data(), parts[4]);
  std::memcpy(base + offsets[5], next.colours.data(), parts[5]);
  Recorder rec(c, &sets);
  Buffer* dst[6] = {&samples, &materials, &tables, &frame, &level_buf, &palette};
  for (int i = 0; i < 6; ++i) rec.copy(staging, offsets[i], *dst[i], 0, parts[i]);
  rec.submit();
  shape = next;
  bytes = width;
  cells = cell_dims;
  levels = std::move(next_levels);
  synced = true;
  std::uint64_t uploaded = 0;
  for (std::uint64_t b : parts) uploaded += b;
  return uploaded;
}

std::uint64_t TerrainRenderer::Impl::upload_rows(const TerrainField& terrain,
                                                 std::span<const Box3i> boxes) {
  const Vec3i n = shape.n;
  const auto w = static_cast<std::uint64_t>(bytes);
  // Staged box after box: each box's codes, then its materials (16-byte aligned parts).
  std::uint64_t total = 0;
  for (const Box3i& b : boxes) {
    const auto v = static_cast<std::uint64_t>(b.volume());
    total += (v * w + 15) / 16 * 16 + (v + 15) / 16 * 16;
  }
  Buffer& staging = c.upload_buffer(total);
  auto* base = static_cast<std::uint8_t*>(staging.mapped());
  // One region per row of a box (rows that continue each other on the device merge: a box
  // spanning whole rows and slices is one region).
  std::vector<VkBufferCopy> codes, mats;
  const auto add = [](std::vector<VkBufferCopy>& list, VkDeviceSize src, VkDeviceSize dst,
                      VkDeviceSize size) {
    if (!list.empty() && list.back().srcOffset + list.back().size == src &&
        list.back().dstOffset + list.back().size == dst)
      list.back().size += size;
    else
      list.push_back({src, dst, size});
  };
  std::uint64_t at = 0, sent = 0;
  for (const Box3i& box : boxes) {
    const auto v = static_cast<std::uint64_t>(box.volume());
    const std::uint64_t material_at = at + (v * w + 15) / 16 * 16;
    terrain.read_codes(box, base + at, base + material_at);
    const auto row_samples = static_cast<std::uint64_t>(box.end.x - box.begin.x);
    std::uint64_t row = 0;
    for (int z = box.begin.z; z < box.end.z; ++z)
      for (int y = box.begin.y; y < box.end.y; ++y, ++row) {
        const std::uint64_t sample =
            static_cast<std::uint64_t>(box.begin.x) +
            static_cast<std::uint64_t>(n.x) *
                (static_cast<std::uint64_t>(y) +
                 static_cast<std::uint64_t>(n.y) * static_cast<std::uint64_t>(z));
        add(codes, at + row * row_samples * w, sample * w, row_samples * w);
        add(mats, material_at + row * row_samples, sample, row_samples);
      }
    at = material_at + (v + 15) / 16 * 16;
    sent += v * (w + 1);
  }
  Recorder rec(c, &sets);
  rec.copy({Recorder::Copy{&staging, &samples, codes}, Recorder::Copy{&staging, &materials, mats}});
  rec.submit();
  return sent;
}

void TerrainRenderer::Impl::ensure_target(int width, int height, VkFormat format) {
  if (target && graphics && target->width() == width && target->height() == height &&
      target->format() == format)
    return;
  if (target) check(vkQueueWaitIdle(c.queue), "vkQueueWaitIdle");  // a frame may still use it
  graphics.reset();
  target.reset();
  sets.reset();
  auto next = std::make_unique<RenderTarget>(c, width, height, format);
  graphics = std::make_unique<GraphicsKernel>(c, shaders::mesh_draw_vert(),
                                              shaders::mesh_draw_frag(), *next);
  target = std::move(next);  // both made: a failure above leaves neither
}

L::MeshParams TerrainRenderer::Impl::params() const {
  L::MeshParams p{};
  p.size = {shape.n.x, shape.n.y, shape.n.z,
            bytes == 1   ? L::VF_MC_I8
            : bytes == 2 ? L::VF_MC_I16
                         : L::VF_MC_F32};
  p.cells = {cells.x, cells.y, cells.z,
             pyramid_kind == Pyramid::kFourToOne ? L::VF_MC_PYRAMID_4 : L::VF_MC_PYRAMID_8};
  p.pass = {0, static_cast<std::int32_t>(levels.size()), INT32_MAX,
            static_cast<std::int32_t>(
                std::min<std::uint32_t>(c.limits.maxComputeWorkGroupCount[0], INT32_MAX))};
  p.iso = 0;
  p.negate = 0;  // the stored codes are negative inside whatever the field's convention
  return p;
}

void TerrainRenderer::Impl::record_frame(Recorder& rec, const TerrainView& o) {
  // The view, as the CPU rasteriser's camera and shading (mesh_raster.cpp).
  L::MeshDrawView v{};
  v.eye = v4(o.eye, o.perspective ? 1 : 0);
  v.right = v4(o.right, o.scale);
  v.up = v4(o.up, static_cast<double>(o.height) / o.width);
  v.forward = v4(o.forward, 1e-3);  // the CPU's near plane
  v.light = v4(o.light_towards.normalized(), o.use_colors && shape.palette ? 1 : 0);
  v.base = {static_cast<float>(o.base_color[0]), static_cast<float>(o.base_color[1]),
            static_cast<float>(o.base_color[2]), 0};
  // Orthographic depth spans the terrain's box in view depth (with a margin).
  double near_depth = std::numeric_limits<double>::infinity(), far_depth = -near_depth;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3d p{shape.origin[0] + (corner & 1 ? (shape.n.x - 1) * shape.spacing : 0),
                  shape.origin[1] + (corner & 2 ? (shape.n.y - 1) * shape.spacing : 0),
                  shape.origin[2] + (corner & 4 ? (shape.n.z - 1) * shape.spacing : 0)};
    const double d = dot(p - o.eye, o.forward);
    near_depth = std::min(near_depth, d);
    far_depth = std::max(far_depth, d);
  }
  const double margin = 1e-3 * (far_depth - near_depth) + shape.spacing;
  v.depth = {static_cast<float>(near_depth - margin), static_cast<float>(far_depth + margin), 0, 0};
  rec.update(view, 0, &v, sizeof v);

  L::MeshParams p = params();
  Binding all[10] = {&samples, &tables, &frame,     &level_buf, &pyramid,
                     &cases,   &view,   &materials, &palette,   &draw};
  const Recorder::Buffers list(all, 10);
  mc::record_pyramid(rec, c, list, p, levels);
  p.pass.x = 0;
  rec.dispatch(c.kernel(shaders::mesh_draw_args()), list, p, 1);
  const int drawn = rec.begin_pass();
  const std::array<float, 4> clear{o.background[0] / 255.0f, o.background[1] / 255.0f,
                                   o.background[2] / 255.0f, 1.0f};
  rec.draw_indirect(*graphics, *target, list, &p, sizeof p, draw, 0, clear);
  rec.end_pass(drawn, "draw");
}

namespace {

void check_frame(const TerrainRenderer::Impl& r, const TerrainView& o) {
  if (!r.synced) throw InvalidArgument("the GPU terrain renderer: no terrain synced yet");
  for (const Vec3d* v : {&o.eye, &o.forward, &o.right, &o.up, &o.light_towards})
    if (!std::isfinite(v->x) || !std::isfinite(v->y) || !std::isfinite(v->z))
      throw InvalidArgument("the GPU terrain renderer: the view has a non-finite vector");
  if (!(o.scale > 0) || !std::isfinite(o.scale))
    throw InvalidArgument("the GPU terrain renderer: the view's scale must be finite and > 0");
  if (o.light_towards.length() == 0)
    throw InvalidArgument("the GPU terrain renderer: the light's direction is zero");
  if (o.width < 1 || o.height < 1 ||
      static_cast<std::uint64_t>(o.width) * static_cast<std::uint64_t>(o.height) > (1u << 28))
    throw InvalidArgument("the GPU terrain renderer: a picture of " + std::to_string(o.width) +
                          " x " + std::to_string(o.height) + " pixels is out of range");
}

}  // namespace

TerrainRenderer::TerrainRenderer(std::shared_ptr<Context> context, Pyramid pyramid) {
  if (!context) throw InvalidArgument("the GPU terrain renderer needs a context");
  Context::Impl& c = context->impl();
  c.require_device();
  if (!c.float64)
    throw GpuUnavailable(
        "Vulkan: the GPU terrain renderer computes marching cubes' vertices in doubles, as the CPU "
        "does, and needs the device feature shaderFloat64, which " +
        c.info.name + " does not have");
  impl_ = std::make_unique<Impl>(std::move(context), pyramid);
}

TerrainRenderer::~TerrainRenderer() {
  // Frames recorded into an application's command buffer may still read these buffers.
  if (impl_ && !impl_->c.lost) vkQueueWaitIdle(impl_->c.queue);
}

Context& TerrainRenderer::context() {
  return *impl_->context;
}

std::uint64_t TerrainRenderer::sync(const TerrainField& terrain) {
  return impl_->upload_whole(terrain);
}

std::uint64_t TerrainRenderer::sync(const TerrainField& terrain, const Box3i& changed) {
  return sync(terrain, std::span<const Box3i>(&changed, 1));
}

std::uint64_t TerrainRenderer::sync(const TerrainField& terrain, std::span<const Box3i> changed) {
  Impl& r = *impl_;
  const Box3i lattice = Box3i::from_size(terrain.size());
  for (const Box3i& b : changed)
    if (!lattice.contains(b))
      throw InvalidArgument("the GPU terrain renderer: the changed box " + to_string(b.begin) +
                            ".." + to_string(b.end) + " leaves the " + to_string(terrain.size()) +
                            " lattice");
  if (!r.synced || !(shape_of(terrain) == r.shape)) return r.upload_whole(terrain);
  // Disjoint boxes: each overlapping pair becomes its union, until none overlap.
  std::vector<Box3i> boxes;
  for (const Box3i& b : changed)
    if (!b.empty()) boxes.push_back(b);
  for (bool merged = true; merged;) {
    merged = false;
    for (std::size_t i = 0; i < boxes.size() && !merged; ++i)
      for (std::size_t j = i + 1; j < boxes.size() && !merged; ++j)
        if (!boxes[i].intersect(boxes[j]).empty()) {
          boxes[i] = boxes[i].unite(boxes[j]);
          boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
        }
  }
  if (boxes.empty()) return 0;
  return r.upload_rows(terrain, boxes);
}

std::uint64_t TerrainRenderer::last_triangles() const {
  if (!impl_->synced || impl_->draw.mapped() == nullptr) return 0;
  std::uint32_t vertices = 0;
  std::memcpy(&vertices, impl_->draw.mapped(), 4);
  return vertices / 3;
}

Image TerrainRenderer::render(const TerrainView& options, TerrainDrawStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  Impl& r = *impl_;
  check_frame(r, options);
  Context::Impl& c = r.c;
  const Counters before = c.counters;
  r.ensure_target(options.width, options.height, VK_FORMAT_R8G8B8A8_UNORM);
  const std::uint64_t pixel_bytes =
      4ull * static_cast<std::uint64_t>(options.width) * static_cast<std::uint64_t>(options.height);
  Buffer& readback = c.readback_buffer(pixel_bytes);
  std::vector<PassTiming> passes;
  {
    Recorder rec(c, &r.sets);
    r.record_frame(rec, options);
    rec.copy_colour(*r.target, readback);
    rec.submit();
    passes = rec.timings();
  }
  Image image(options.width, options.height);
  const auto* rgba = static_cast<const std::uint8_t*>(readback.mapped());
  for (std::size_t i = 0, count = image.rgb.size() / 3; i < count; ++i)
    std::memcpy(&image.rgb[3 * i], rgba + 4 * i, 3);
  if (stats) {
    const Counters& now = c.counters;
    stats->dispatches = now.dispatches - before.dispatches;
    stats->draws = now.draws - before.draws;
    stats->submits = now.submits - before.submits;
    stats->fence_waits = now.fence_waits - before.fence_waits;
    stats->bytes_uploaded = now.bytes_uploaded - before.bytes_uploaded;
    stats->bytes_downloaded = now.bytes_downloaded - before.bytes_downloaded;
    stats->triangles = last_triangles();
    stats->pyramid_levels = static_cast<int>(r.levels.size());
    stats->passes = std::move(passes);
    stats->ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  return image;
}

VkBuffer record_render(TerrainRenderer& renderer, VkCommandBuffer cmd, const TerrainView& options,
                       PixelOrder order) {
  TerrainRenderer::Impl& r = renderer.impl();
  check_frame(r, options);
  r.ensure_target(options.width, options.height,
                  order == PixelOrder::kBgra ? VK_FORMAT_B8G8R8A8_UNORM : VK_FORMAT_R8G8B8A8_UNORM);
  const VkDeviceSize bytes =
      4ull * static_cast<VkDeviceSize>(options.width) * static_cast<VkDeviceSize>(options.height);
  if (r.pixels.size() < bytes) r.pixels = Buffer(r.c, bytes, kUsage, false);
  Recorder rec(r.c, cmd, r.sets);
  r.record_frame(rec, options);
  rec.copy_colour(*r.target, r.pixels);
  rec.expose(r.pixels, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  // The draw's count, for last_triangles() once the application's fence has signalled.
  rec.expose(r.draw, VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
  return r.pixels.handle();
}

}  // namespace voxfield::gpu
