// voxfield GPU backend — frames of the ray-marching compute shader (shaders/render.comp beside
// this file) over a scene resident on the device (frames.h).
//
// Frame parameters travel inside the command buffer (vkCmdUpdateBuffer), so recording a frame
// into an application's command buffer needs no host-visible memory of voxfield's.
#include "frames.h"

#include <chrono>
#include <cstring>

#include "gpu/split_buffer.h"

#include "render_shaders.h"
#include "shaders/layout.h"
#include "voxfield/detail/assert.h"
#include "voxfield/gpu_distance.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

L::vec4f v4(const Vec3d& v, double w = 0) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
          static_cast<float>(w)};
}

}  // namespace

int FrameScene::slice_z(const RenderOptions& o) const {
  const int z = o.slice_z ? *o.slice_z : (box.begin.z + box.end.z) / 2;
  if (z < box.begin.z || z >= box.end.z)
    throw InvalidArgument("render: slice z=" + std::to_string(z) + " lies outside the box " +
                          to_string(box));
  return z;
}

void check_frame(const FrameScene& s, const RenderOptions& o) {
  if (o.view == RenderView::kDistance) s.slice_z(o);  // throws for a cut outside the box
  if (o.skip != SkipMode::kDistance)
    throw InvalidArgument("GPU: the Vulkan ray marcher always skips by distance");
  if (o.width <= 0 || o.height <= 0 || o.width > 16384 || o.height > 16384)
    throw InvalidArgument("render: image size out of range (1..16384 per side)");
  if ((o.ambient_occlusion || o.soft_shadows) && !s.has_light)
    throw InvalidArgument(
        "render: ambient occlusion and soft shadows need the scene's lighting field");
  if (!(o.sun_direction.length() > 0))
    throw InvalidArgument("render: the sun direction must be non-zero");
}

Frames::Frames(Context& context)
    : context_(context),
      ctx_(context.impl()),
      kernel_(ctx_.kernel(shaders::render())),
      sets_(ctx_) {}

void Frames::ensure_pixels(VkDeviceSize bytes) {
  // The shader writes the image through split_buffer.glsl's windows.
  check_split_binding(ctx_, bytes, "render: the image");
  if (pixels_.handle() != VK_NULL_HANDLE && pixels_.size() >= bytes) return;
  pixels_ = Buffer(ctx_, bytes, kSceneBufferUsage, false);
  descriptors_stale_ = true;
}

void Frames::prepare_approximation(const FrameScene& s, const RenderOptions& o) {
  if (o.view != RenderView::kError) return;
  const Algorithm algorithm = o.error_algorithm;
  if (approx_scene_ == s.id && approx_generation_ == s.generation &&
      approx_algorithm_ == static_cast<int>(algorithm))
    return;
  // Nothing resident until the new approximation is made (a throw below leaves none, so the next
  // error frame computes it again).
  approx_computed_.reset();
  approx_algorithm_ = -1;
  // The skip source reads no sites; the device's algorithms take unit spacing only (brute force,
  // the CPU's reference, and a skip field of another spacing stay on the CPU).
  DistanceOptions options = s.skip_options;
  options.nearest_sites = false;
  const bool unit = options.spacing == std::array<double, 3>{1, 1, 1};
  if (algorithm == Algorithm::kBrute || algorithm == Algorithm::kBruteChunked || !unit)
    approx_computed_ = render_detail::approximation(s.table, *s.world, options, algorithm);
  else
    approx_computed_ = render_detail::make_skip_source(
        s.table, *s.world,
        voxfield::gpu::compute_distance_field(
            context_, *s.world, options, render_detail::approximation_options(s.box, algorithm)));
  approx_scene_ = s.id;
  approx_generation_ = s.generation;
  approx_algorithm_ = static_cast<int>(algorithm);
  approx_inv_scale_ = approx_computed_->inv_scale;
}

void Frames::record_approximation(Recorder& rec, const FrameScene& s) {
  if (!approx_computed_) return;
  // Kept pending until its copy is recorded: a buffer that fails to allocate leaves it for the
  // next frame.
  const SkipSource& approx = *approx_computed_;
  const std::size_t chunks = s.table.chunk_count();
  std::vector<std::uint32_t> info(2 * chunks);
  for (std::size_t i = 0; i < chunks; ++i) {
    const std::uint32_t slot = approx.cells.slot[i];
    info[2 * i] = slot == BrickedChunks<std::uint16_t>::kUniform ? L::VF_UNIFORM : slot;
    info[2 * i + 1] = static_cast<std::uint32_t>(approx.cells.uniform[i]) |
                      (std::uint32_t{approx.chunk_min[i]} << 16);
  }
  const std::size_t info_bytes = info.size() * 4;
  const std::size_t arena_bytes = std::size_t{approx.cells.slots_used} * approx.cells.slot_bytes();
  check_split_binding(ctx_, arena_bytes, "render: the error view's approximation's arena");
  if (approx_info_.size() < std::max<std::size_t>(info_bytes, 16) ||
      approx_arena_.size() < std::max<std::size_t>(arena_bytes, 16)) {
    approx_info_ = Buffer(ctx_, std::max<std::size_t>(info_bytes, 16), kSceneBufferUsage, false);
    approx_arena_ = Buffer(ctx_, std::max<std::size_t>(arena_bytes, 16), kSceneBufferUsage, false);
    descriptors_stale_ = true;
  }
  if (approx_staging_.size() < info_bytes + arena_bytes)
    approx_staging_ = Buffer(ctx_, info_bytes + arena_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                             /*host_visible=*/true);
  auto* base = static_cast<std::uint8_t*>(approx_staging_.mapped());
  std::memcpy(base, info.data(), info_bytes);
  if (arena_bytes > 0) std::memcpy(base + info_bytes, approx.cells.arena.data(), arena_bytes);
  const VkBufferCopy to_info{0, 0, info_bytes}, to_arena{info_bytes, 0, arena_bytes};
  rec.copy({{&approx_staging_, &approx_info_, {&to_info, 1}},
            {&approx_staging_, &approx_arena_,
             arena_bytes > 0 ? std::span(&to_arena, 1) : std::span<const VkBufferCopy>()}});
  approx_computed_.reset();
}

void Frames::record_render(Recorder& rec, const FrameScene& s, const Camera& camera,
                           const RenderOptions& o, bool bgra, bool timed) {
  check_frame(s, o);
  ensure_pixels(static_cast<VkDeviceSize>(o.width) * o.height * 4);
  if (!params_.handle()) params_ = Buffer(ctx_, sizeof(L::RenderParams), kSceneBufferUsage, false);
  const bool error = o.view == RenderView::kError;
  if (error) {
    VOXFIELD_ASSERT(approx_scene_ == s.id && approx_generation_ == s.generation &&
                    approx_algorithm_ == static_cast<int>(o.error_algorithm));  // prepared
    record_approximation(rec, s);
  }
  for (Buffer* b : {&approx_info_, &approx_arena_})
    if (b->handle() == VK_NULL_HANDLE)
      *b = Buffer(ctx_, 16, kSceneBufferUsage, false);  // bound even when unused
  if (descriptors_stale_) {
    sets_.reset();  // the last frame that used them has completed (gpu_render_vulkan.h)
    descriptors_stale_ = false;
  }

  const Camera::Projector pj = camera.projector(o.width, o.height);
  L::RenderParams rp{};
  rp.eye = v4(pj.eye, pj.projection == Camera::Projection::kOrthographic ? 1 : 0);
  rp.forward = v4(pj.forward, pj.sky_scale.x);
  rp.right = v4(pj.right, pj.sky_scale.y);
  rp.up = v4(pj.up, pj.sky_scale.z);
  rp.sun = v4(o.sun_direction.normalized(), o.fog_density);
  rp.box_begin = {s.box.begin.x, s.box.begin.y, s.box.begin.z, 0};
  rp.box_end = {s.box.end.x, s.box.end.y, s.box.end.z, 0};
  const Vec3i first = s.table.first_chunk(), dims = s.table.chunk_dims();
  rp.first_chunk = {first.x, first.y, first.z, s.table.shift()};
  rp.chunk_dims = {dims.x, dims.y, dims.z, static_cast<std::int32_t>(s.chunk_volume)};
  rp.width = static_cast<std::uint32_t>(o.width);
  rp.height = static_cast<std::uint32_t>(o.height);
  rp.scale = static_cast<float>(pj.scale);
  rp.footprint_scale = static_cast<float>(pj.footprint_scale);
  rp.metric = static_cast<std::uint32_t>(s.metric);
  rp.skip_inv_scale = static_cast<float>(s.skip_inv_scale);
  rp.light_inv_scale = static_cast<float>(s.light_inv_scale);
  const bool distance = o.view == RenderView::kDistance;
  // The distance and error views shade without shadows, as the CPU's do.
  rp.flags = (o.ambient_occlusion ? L::VF_RENDER_AO : 0u) |
             (o.soft_shadows && !distance && !error ? L::VF_RENDER_SHADOWS : 0u) |
             (o.view == RenderView::kChunks ? L::VF_RENDER_CHUNKS : 0u) |
             (s.has_light ? L::VF_RENDER_HAS_LIGHT : 0u) | (bgra ? L::VF_RENDER_BGRA : 0u) |
             (distance ? L::VF_RENDER_DISTANCE : 0u) | (error ? L::VF_RENDER_ERROR : 0u);
  rp.approx_inv_scale = static_cast<float>(approx_inv_scale_);
  rp.heat_top = 1;
  rp.part_shift = split_part_shift(ctx_);
  if (distance) {
    rp.slice_z = s.slice_z(o);
    if (s.heat_top) rp.heat_top = s.heat_top(rp.slice_z);
  }

  rec.update(params_, 0, &rp, sizeof rp);
  if (distance && s.record_heat) s.record_heat(rec, params_, rp.slice_z);
  const auto skip = split_bindings(*s.skip, ctx_), light = split_bindings(*s.light, ctx_),
             pixels = split_bindings(pixels_, ctx_), approx = split_bindings(approx_arena_, ctx_);
  const Binding bound[] = {&params_,  s.info,        skip[0],   light[0],  s.palette,
                           pixels[0], &approx_info_, approx[0], skip[1],   skip[2],
                           skip[3],   light[1],      light[2],  light[3],  pixels[1],
                           pixels[2], pixels[3],     approx[1], approx[2], approx[3]};
  const int pass = timed ? rec.begin_pass() : -1;
  rec.dispatch(kernel_, bound, nullptr, 0, static_cast<std::uint64_t>(o.width) * o.height);
  rec.end_pass(pass, "render");
}

Image render_and_read(Context::Impl& ctx, Frames& frames, const FrameScene& s,
                      const std::function<void(Recorder&)>& record_first, const Camera& camera,
                      const RenderOptions& o, RenderStats* stats,
                      std::vector<PassTiming>* timings) {
  check_frame(s, o);
  // The error view's approximation first (its own submit, outside the frame's time, as the CPU
  // renderer leaves its approximation out of RenderStats::ms).
  frames.prepare_approximation(s, o);
  const VkDeviceSize image_bytes = static_cast<VkDeviceSize>(o.width) * o.height * 4;
  Buffer& readback = ctx.readback_buffer(image_bytes);
  const auto t0 = std::chrono::steady_clock::now();
  Recorder rec(ctx, &frames.sets());
  if (record_first) record_first(rec);
  frames.record_render(rec, s, camera, o, /*bgra=*/false, timings != nullptr);
  rec.copy(frames.pixels(), 0, readback, 0, image_bytes);
  rec.submit();
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (timings) *timings = rec.timings();
  Image image(o.width, o.height);
  const auto* px = static_cast<const std::uint32_t*>(readback.mapped());
  for (std::size_t i = 0; i < static_cast<std::size_t>(o.width) * o.height; ++i) {
    image.rgb[3 * i] = static_cast<std::uint8_t>(px[i] & 0xFF);
    image.rgb[3 * i + 1] = static_cast<std::uint8_t>((px[i] >> 8) & 0xFF);
    image.rgb[3 * i + 2] = static_cast<std::uint8_t>((px[i] >> 16) & 0xFF);
  }
  if (stats) {
    *stats = RenderStats{};
    stats->ms = ms;  // (upload +) render + read-back, as the caller waits for it
    stats->width = o.width;
    stats->height = o.height;
    stats->primary.rays = static_cast<std::int64_t>(o.width) * o.height;
  }
  return image;
}

}  // namespace voxfield::gpu
