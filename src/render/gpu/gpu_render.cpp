// voxfield GPU backend — frames from the ray-marching compute shader (shaders/render.comp beside
// this file), over a scene kept resident on the GPU.
//
// The scene's bricked arenas (src/render/scene_impl.h: distance + material cells, the lighting
// field, per-chunk flags) are copied as they are, so the shader walks exactly the data the CPU
// walks. The first sync copies the whole scene; after RenderScene::update() only the chunks it
// re-read (their slots in both arenas and their chunk-table entries) and the palette are copied.
// Frame parameters travel inside the command buffer (vkCmdUpdateBuffer), so recording a frame
// into an application's command buffer needs no host-visible memory of voxfield's.
#include <chrono>
#include <cstring>
#include <optional>

#include "../scene_impl.h"
#include "gpu/recorder.h"
#include "render_shaders.h"
#include "shaders/layout.h"
#include "voxfield/detail/assert.h"
#include "voxfield/gpu_distance.h"
#include "voxfield/gpu_render_vulkan.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

L::vec4f v4(const Vec3d& v, double w = 0) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
          static_cast<float>(w)};
}

// The shader's four words per chunk: skip slot, (uniform cell | chunk min << 16 | empty << 24 |
// dense << 25), light slot, light uniform value.
std::array<std::uint32_t, 4> chunk_info(const RenderScene::Impl& s, std::size_t i) {
  std::array<std::uint32_t, 4> w{};
  w[0] = s.skip.cells.slot[i] == BrickedChunks<std::uint16_t>::kUniform ? L::VF_UNIFORM
                                                                        : s.skip.cells.slot[i];
  w[1] = static_cast<std::uint32_t>(s.skip.cells.uniform[i]) |
         (std::uint32_t{s.skip.chunk_min[i]} << 16) | (s.empty_chunk[i] ? 1u << 24 : 0u) |
         (s.dense_material[i] ? 1u << 25 : 0u);
  if (s.has_light) {
    w[2] =
        s.light.slot[i] == BrickedChunks<std::uint8_t>::kUniform ? L::VF_UNIFORM : s.light.slot[i];
    w[3] = s.light.uniform[i];
  } else {
    w[2] = L::VF_UNIFORM;
  }
  return w;
}

void check_options(const RenderScene::Impl& s, const RenderOptions& o) {
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

}  // namespace

// The GPU copy of a RenderScene and the buffers a frame writes.
class ResidentScene {
 public:
  // The ray marcher's kernel is made with the scene (on first use in the process), not inside
  // the first frame.
  explicit ResidentScene(Context& context)
      : context_(context),
        ctx_(context.impl()),
        kernel_(ctx_.kernel(shaders::render())),
        sets_(ctx_) {}
  ResidentScene(const ResidentScene&) = delete;
  ResidentScene& operator=(const ResidentScene&) = delete;

  // Records the copies that bring the GPU copy up to date with `scene` (staged in the context's
  // upload buffer). Returns false, recording nothing, when the copy is already current.
  bool record_sync(Recorder& rec, const RenderScene& scene);
  // Whether the GPU copy already equals `scene` (record_sync would record nothing).
  bool current(const RenderScene& scene) const {
    const RenderScene::Impl& s = scene.impl();
    return scene_ == &s && scene_id_ == s.id && synced_generation_ == s.chunk_generation &&
           synced_palette_ == s.palette_generation &&
           skip_.size() >= std::max<std::size_t>(s.skip.cells.arena.size(), 16) &&
           light_.size() >= std::max<std::size_t>(s.has_light ? s.light.arena.size() : 0, 16);
  }
  // Computes the error view's approximation of `s` when a frame of `o` needs one that is not
  // resident: on the device, by the dissertation's GPU algorithms (gpu_distance.h; brute force,
  // the CPU's reference, on the CPU). Its own submit and fence wait, so it runs before a frame's
  // recording starts (the context's upload buffer may hold that recording's staged copies).
  void prepare_approximation(const RenderScene::Impl& s, const RenderOptions& o);
  // Records a frame: parameters and the dispatch. Needs a synced scene.
  void record_render(Recorder& rec, const Camera& camera, const RenderOptions& o, bool bgra,
                     bool timed);

  Buffer& pixels() { return pixels_; }
  // The frame's descriptor sets: kept across frames, recycled when buffers are replaced.
  DescriptorArena& sets() { return sets_; }
  const RenderScene::Impl* scene() const { return scene_; }

 private:
  void ensure_pixels(VkDeviceSize bytes);
  // Records the copy of the approximation prepare_approximation() computed, if any (staged in a
  // buffer of its own so a sync in the same command buffer does not overwrite it).
  void record_approximation(Recorder& rec);

  Context& context_;
  Context::Impl& ctx_;
  const Kernel& kernel_;
  const RenderScene::Impl* scene_ = nullptr;
  std::uint64_t scene_id_ = 0;
  std::vector<std::uint64_t> synced_generation_;
  std::uint64_t synced_palette_ = 0;
  Buffer params_, info_, skip_, light_, palette_, pixels_;
  // Replaced buffers, kept until the next sync: by then the copies out of them and the frames
  // that read them have completed (one frame in flight).
  std::vector<Buffer> retired_;
  Buffer approx_info_, approx_arena_, approx_staging_;
  std::optional<SkipSource> approx_computed_;  // prepared, not yet recorded
  std::uint64_t approx_scene_ = 0,
                approx_generation_ = 0;  // what the resident approximation was made from
  int approx_algorithm_ = -1;
  double approx_inv_scale_ = 1;
  DescriptorArena sets_;
  bool descriptors_stale_ = false;
};

namespace {

constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

// Copy regions into one destination buffer, staged contiguously.
struct Staged {
  std::vector<VkBufferCopy> regions;
};

}  // namespace

bool ResidentScene::record_sync(Recorder& rec, const RenderScene& scene) {
  const RenderScene::Impl& s = scene.impl();
  const std::size_t chunks = s.table.chunk_count();
  const std::size_t skip_live = std::size_t{s.skip.cells.slots_used} * s.skip.cells.slot_bytes();
  const std::size_t light_live =
      s.has_light ? std::size_t{s.light.slots_used} * s.light.slot_bytes() : 0;
  bool whole = scene_ != &s || scene_id_ != s.id || synced_generation_.size() != chunks;

  // Device buffers as large as the host arenas' capacity, so growth is rare. A new scene gets
  // everything copied; an arena that outgrew its buffer moves to a larger one on the GPU (the old
  // buffer is retired until this submission has completed), so only the changed chunks travel.
  retired_.clear();
  std::vector<std::pair<Buffer*, Buffer>> grown;
  auto ensure = [&](Buffer& b, std::size_t bytes, bool keep) {
    bytes = std::max<std::size_t>(bytes, 16);
    if (b.handle() != VK_NULL_HANDLE && b.size() >= bytes) return;
    Buffer bigger(ctx_, bytes, kUsage, false);
    if (keep && !whole && b.handle() != VK_NULL_HANDLE) {
      grown.emplace_back(&b, std::move(b));
    } else {
      whole = true;
      if (b.handle() != VK_NULL_HANDLE)
        retired_.push_back(std::move(b));  // a frame may still read it
    }
    b = std::move(bigger);
    descriptors_stale_ = true;
  };
  ensure(params_, sizeof(L::RenderParams), false);
  ensure(info_, chunks * 16, false);
  ensure(palette_, 256 * 16, false);
  ensure(skip_, s.skip.cells.arena.size(), true);
  ensure(light_, s.has_light ? s.light.arena.size() : 0, true);
  if (whole) grown.clear();  // everything is copied from the host anyway
  // The recorder orders these copies after the frames submitted earlier that read the buffers
  // they write (an application that records frames into its own command buffers need not wait
  // for one before syncing), and the moved contents before the changed chunks written over them.
  for (auto& [now, old] : grown) {
    rec.copy(old, 0, *now, 0, old.size());
    retired_.push_back(std::move(old));
  }

  std::vector<std::size_t> changed;
  const bool palette_changed = whole || synced_palette_ != s.palette_generation;
  if (!whole) {
    for (std::size_t i = 0; i < chunks; ++i)
      if (s.chunk_generation[i] != synced_generation_[i]) changed.push_back(i);
    if (changed.empty() && !palette_changed) return false;
  }

  // Stage: palette, then chunk-table entries, then slots of both arenas.
  const std::size_t info_count = whole ? chunks : changed.size();
  std::size_t staged_bytes = (palette_changed ? 256 * 16 : 0) + info_count * 16;
  staged_bytes +=
      whole
          ? skip_live + light_live
          : changed.size() * (s.skip.cells.slot_bytes() + (s.has_light ? s.light.slot_bytes() : 0));
  Buffer& upload = ctx_.upload_buffer(staged_bytes);
  auto* base = static_cast<std::uint8_t*>(upload.mapped());
  VkDeviceSize at = 0;
  auto stage = [&](Staged& into, VkDeviceSize dst, const void* data, std::size_t n) {
    if (n == 0) return;
    std::memcpy(base + at, data, n);
    into.regions.push_back({at, dst, n});
    at += n;
  };
  Staged palette_copy, info_copy, skip_copy, light_copy;
  if (palette_changed) {
    std::vector<float> palette(256 * 4, 0.0f);
    for (int m = 0; m < 256; ++m)
      for (int c = 0; c < 3; ++c)
        palette[static_cast<std::size_t>(4 * m + c)] =
            s.albedo[static_cast<std::size_t>(m)][static_cast<std::size_t>(c)];
    stage(palette_copy, 0, palette.data(), palette.size() * 4);
  }
  if (whole) {
    std::vector<std::uint32_t> info(4 * chunks);
    for (std::size_t i = 0; i < chunks; ++i) {
      const auto w = chunk_info(s, i);
      std::memcpy(&info[4 * i], w.data(), 16);
    }
    stage(info_copy, 0, info.data(), info.size() * 4);
    stage(skip_copy, 0, s.skip.cells.arena.data(), skip_live);
    if (s.has_light) stage(light_copy, 0, s.light.arena.data(), light_live);
  } else {
    for (std::size_t i : changed) {
      const auto w = chunk_info(s, i);
      stage(info_copy, i * 16, w.data(), 16);
      const std::uint32_t slot = s.skip.cells.slot[i];
      if (slot != BrickedChunks<std::uint16_t>::kUniform) {
        const std::size_t n = s.skip.cells.slot_bytes();
        stage(skip_copy, std::size_t{slot} * n, s.skip.cells.arena.data() + std::size_t{slot} * n,
              n);
      }
      if (s.has_light && s.light.slot[i] != BrickedChunks<std::uint8_t>::kUniform) {
        const std::size_t n = s.light.slot_bytes();
        stage(light_copy, std::size_t{s.light.slot[i]} * n,
              s.light.arena.data() + std::size_t{s.light.slot[i]} * n, n);
      }
    }
  }
  rec.copy({{&upload, &palette_, palette_copy.regions},
            {&upload, &info_, info_copy.regions},
            {&upload, &skip_, skip_copy.regions},
            {&upload, &light_, light_copy.regions}});
  scene_ = &s;
  scene_id_ = s.id;
  synced_generation_ = s.chunk_generation;
  synced_palette_ = s.palette_generation;
  return true;
}

void ResidentScene::ensure_pixels(VkDeviceSize bytes) {
  if (pixels_.handle() != VK_NULL_HANDLE && pixels_.size() >= bytes) return;
  pixels_ = Buffer(ctx_, bytes, kUsage, false);
  descriptors_stale_ = true;
}

void ResidentScene::prepare_approximation(const RenderScene::Impl& s, const RenderOptions& o) {
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
    approx_computed_ = s.approximation(algorithm);
  else
    approx_computed_ = s.make_skip_source(voxfield::gpu::compute_distance_field(
        context_, *s.world, options, s.approximation_options(algorithm)));
  approx_scene_ = s.id;
  approx_generation_ = s.generation;
  approx_algorithm_ = static_cast<int>(algorithm);
  approx_inv_scale_ = approx_computed_->inv_scale;
}

void ResidentScene::record_approximation(Recorder& rec) {
  if (!approx_computed_) return;
  // Kept pending until its copy is recorded: a buffer that fails to allocate leaves it for the
  // next frame.
  const SkipSource& approx = *approx_computed_;
  const RenderScene::Impl& s = *scene_;
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
  if (approx_info_.size() < std::max<std::size_t>(info_bytes, 16) ||
      approx_arena_.size() < std::max<std::size_t>(arena_bytes, 16)) {
    approx_info_ = Buffer(ctx_, std::max<std::size_t>(info_bytes, 16), kUsage, false);
    approx_arena_ = Buffer(ctx_, std::max<std::size_t>(arena_bytes, 16), kUsage, false);
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

void ResidentScene::record_render(Recorder& rec, const Camera& camera, const RenderOptions& o,
                                  bool bgra, bool timed) {
  if (!scene_) throw InvalidArgument("GPU render: no scene synced yet");
  const RenderScene::Impl& s = *scene_;
  check_options(s, o);
  ensure_pixels(static_cast<VkDeviceSize>(o.width) * o.height * 4);
  const bool error = o.view == RenderView::kError;
  if (error) {
    VOXFIELD_ASSERT(approx_scene_ == s.id && approx_generation_ == s.generation &&
                    approx_algorithm_ == static_cast<int>(o.error_algorithm));  // prepared
    record_approximation(rec);
  }
  for (Buffer* b : {&approx_info_, &approx_arena_})
    if (b->handle() == VK_NULL_HANDLE)
      *b = Buffer(ctx_, 16, kUsage, false);  // bound even when unused
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
  rp.chunk_dims = {dims.x, dims.y, dims.z, static_cast<std::int32_t>(s.skip.cells.chunk_volume)};
  rp.width = static_cast<std::uint32_t>(o.width);
  rp.height = static_cast<std::uint32_t>(o.height);
  rp.scale = static_cast<float>(pj.scale);
  rp.footprint_scale = static_cast<float>(pj.footprint_scale);
  rp.metric = static_cast<std::uint32_t>(s.skip.metric);
  rp.skip_inv_scale = static_cast<float>(s.skip.inv_scale);
  rp.light_inv_scale = static_cast<float>(s.light_inv_scale);
  const bool distance = o.view == RenderView::kDistance;
  // The distance and error views shade without shadows, as the CPU's do.
  rp.flags = (o.ambient_occlusion ? L::VF_RENDER_AO : 0u) |
             (o.soft_shadows && !distance && !error ? L::VF_RENDER_SHADOWS : 0u) |
             (o.view == RenderView::kChunks ? L::VF_RENDER_CHUNKS : 0u) |
             (s.has_light ? L::VF_RENDER_HAS_LIGHT : 0u) | (bgra ? L::VF_RENDER_BGRA : 0u) |
             (distance ? L::VF_RENDER_DISTANCE : 0u) | (error ? L::VF_RENDER_ERROR : 0u);
  rp.approx_inv_scale = static_cast<float>(approx_inv_scale_);
  if (distance) {
    rp.slice_z = s.slice_z(o);
    rp.heat_max = static_cast<float>(s.heat_max(rp.slice_z));
  }

  rec.update(params_, 0, &rp, sizeof rp);
  Buffer* const bound[] = {&params_,  &info_,   &skip_,        &light_,
                           &palette_, &pixels_, &approx_info_, &approx_arena_};
  const int pass = timed ? rec.begin_pass() : -1;
  rec.dispatch(kernel_, bound, nullptr, 0, static_cast<std::uint64_t>(o.width) * o.height);
  rec.end_pass(pass, "render");
}

namespace {

// Records the frame, reads it back and converts it to an Image: one submit (and, for an error
// view whose approximation is not resident, the approximation's before it).
Image render_and_read(Context::Impl& ctx, ResidentScene& resident, const RenderScene* sync,
                      const Camera& camera, const RenderOptions& o, RenderStats* stats,
                      std::vector<PassTiming>* timings) {
  if (!sync && !resident.scene()) throw InvalidArgument("GPU render: no scene synced yet");
  check_options(sync ? sync->impl() : *resident.scene(), o);
  // The error view's approximation first (its own submit, outside the frame's time, as the CPU
  // renderer leaves its approximation out of RenderStats::ms).
  resident.prepare_approximation(sync ? sync->impl() : *resident.scene(), o);
  const VkDeviceSize image_bytes = static_cast<VkDeviceSize>(o.width) * o.height * 4;
  Buffer& readback = ctx.readback_buffer(image_bytes);
  const auto t0 = std::chrono::steady_clock::now();
  Recorder rec(ctx, &resident.sets());
  if (sync) resident.record_sync(rec, *sync);
  resident.record_render(rec, camera, o, /*bgra=*/false, timings != nullptr);
  rec.copy(resident.pixels(), 0, readback, 0, image_bytes);
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

}  // namespace

Image render(Context& context, const RenderScene& scene, const Camera& camera,
             const RenderOptions& o, RenderStats* stats, std::vector<PassTiming>* timings) {
  check_options(scene.impl(), o);
  ResidentScene resident(context);
  return render_and_read(context.impl(), resident, &scene, camera, o, stats, timings);
}

// ---- SceneRenderer
// ----------------------------------------------------------------------------------

struct SceneRenderer::Impl {
  std::shared_ptr<Context> context;
  ResidentScene resident;
  explicit Impl(std::shared_ptr<Context> c) : context(std::move(c)), resident(*context) {}
};

SceneRenderer::SceneRenderer(std::shared_ptr<Context> context) {
  if (!context) throw InvalidArgument("gpu::SceneRenderer: no context");
  impl_ = std::make_unique<Impl>(std::move(context));
}

SceneRenderer::~SceneRenderer() = default;

bool SceneRenderer::sync(const RenderScene& scene) {
  if (impl_->resident.current(scene)) return false;
  Recorder rec(impl_->context->impl(), &impl_->resident.sets());
  impl_->resident.record_sync(rec, scene);
  rec.submit();
  return true;
}

Image SceneRenderer::render(const Camera& camera, const RenderOptions& options, RenderStats* stats,
                            std::vector<PassTiming>* timings) {
  return render_and_read(impl_->context->impl(), impl_->resident, nullptr, camera, options, stats,
                         timings);
}

Context& SceneRenderer::context() {
  return *impl_->context;
}

VkBuffer record_render(SceneRenderer& renderer, VkCommandBuffer cmd, const Camera& camera,
                       const RenderOptions& options, PixelOrder order) {
  ResidentScene& r = renderer.impl().resident;
  if (!r.scene()) throw InvalidArgument("GPU render: no scene synced yet");
  check_options(*r.scene(), options);  // before computing an approximation for a frame refused
  r.prepare_approximation(*r.scene(), options);
  Recorder rec(renderer.context().impl(), cmd, r.sets());
  r.record_render(rec, camera, options, order == PixelOrder::kBgra, /*timed=*/false);
  // The application copies the pixels out with a transfer.
  rec.expose(r.pixels(), VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  return r.pixels().handle();
}

}  // namespace voxfield::gpu
