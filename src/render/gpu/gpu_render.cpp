// voxfield GPU backend — a host RenderScene kept resident on the GPU, and its frames (frames.h).
//
// The scene's bricked arenas (src/render/scene_impl.h: distance + material cells, the lighting
// field, per-chunk flags) are copied as they are, so the shader walks exactly the data the CPU
// walks. The first sync copies the whole scene; after RenderScene::update() only the chunks it
// re-read (their slots in both arenas and their chunk-table entries) and the palette are copied.
#include <cstring>

#include "../scene_impl.h"
#include "frames.h"
#include "gpu/recorder.h"
#include "gpu/split_buffer.h"
#include "shaders/layout.h"
#include "voxfield/gpu_render_vulkan.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

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

}  // namespace

// The GPU copy of a RenderScene, and its frames.
class ResidentScene {
 public:
  explicit ResidentScene(Context& context) : ctx_(context.impl()), frames_(context) {}
  ResidentScene(const ResidentScene&) = delete;
  ResidentScene& operator=(const ResidentScene&) = delete;

  // Records the copies that bring the GPU copy up to date with `scene` (staged in the context's
  // upload buffer). Returns false, recording nothing, when the copy is already current.
  bool record_sync(Recorder& rec, const RenderScene& scene);
  // Whether the GPU copy already equals `scene` (record_sync would record nothing).
  bool current(const RenderScene& scene) const {
    const RenderScene::Impl& s = scene.impl();
    return scene_ == &s && scene_id_ == s.id && synced_generation_ == s.chunk_generation &&
           synced_palette_ == s.palette_generation && skip_.size() >= skip_bytes(s) &&
           light_.size() >= light_bytes(s);
  }
  // What a frame of `s` reads, with this copy's buffers.
  FrameScene frame_scene(const RenderScene::Impl& s) {
    FrameScene f;
    f.world = s.world;
    f.box = s.box;
    f.table = s.table;
    f.chunk_volume = s.skip.cells.chunk_volume;
    f.metric = s.skip.metric;
    f.skip_inv_scale = s.skip.inv_scale;
    f.light_inv_scale = s.light_inv_scale;
    f.has_light = s.has_light;
    f.skip_options = s.skip_options;
    f.id = s.id;
    f.generation = s.generation;
    f.info = &info_;
    f.skip = &skip_;
    f.light = &light_;
    f.palette = &palette_;
    f.heat_top = [&s](int z) { return s.heat_top(z); };
    return f;
  }
  Frames& frames() { return frames_; }
  const RenderScene::Impl* scene() const { return scene_; }

 private:
  // Device bytes of the arenas: the host arenas' capacity, so growth is rare, within what the
  // shaders can bind (split_buffer.h); never less than their live slots.
  static std::size_t skip_live(const RenderScene::Impl& s) {
    return std::size_t{s.skip.cells.slots_used} * s.skip.cells.slot_bytes();
  }
  static std::size_t light_live(const RenderScene::Impl& s) {
    return s.has_light ? std::size_t{s.light.slots_used} * s.light.slot_bytes() : 0;
  }
  std::size_t arena_bytes(std::size_t capacity, std::size_t live) const {
    return std::max<std::size_t>(
        {std::min<std::size_t>(capacity, split_capacity_bytes(ctx_)), live, 16});
  }
  std::size_t skip_bytes(const RenderScene::Impl& s) const {
    return arena_bytes(s.skip.cells.arena.size(), skip_live(s));
  }
  std::size_t light_bytes(const RenderScene::Impl& s) const {
    return arena_bytes(s.has_light ? s.light.arena.size() : 0, light_live(s));
  }

  Context::Impl& ctx_;
  Frames frames_;
  const RenderScene::Impl* scene_ = nullptr;
  std::uint64_t scene_id_ = 0;
  std::vector<std::uint64_t> synced_generation_;
  std::uint64_t synced_palette_ = 0;
  Buffer info_, skip_, light_, palette_;
  // Replaced buffers, kept until the next sync: by then the copies out of them and the frames
  // that read them have completed (one frame in flight).
  std::vector<Buffer> retired_;
};

namespace {

// Copy regions into one destination buffer, staged contiguously.
struct Staged {
  std::vector<VkBufferCopy> regions;
};

}  // namespace

bool ResidentScene::record_sync(Recorder& rec, const RenderScene& scene) {
  const RenderScene::Impl& s = scene.impl();
  const std::size_t chunks = s.table.chunk_count();
  const std::size_t skip_live = ResidentScene::skip_live(s),
                    light_live = ResidentScene::light_live(s);
  check_whole_binding(ctx_, chunks * 16,
                      "render: the chunk table of " + std::to_string(chunks) + " chunks");
  // The render shader binds each arena as split_buffer.h's windows.
  check_split_binding(ctx_, skip_live, "render: the scene's cell arena");
  check_split_binding(ctx_, light_live, "render: the scene's lighting arena");
  bool whole = scene_ != &s || scene_id_ != s.id || synced_generation_.size() != chunks;

  // Device buffers as large as the host arenas' capacity, so growth is rare. A new scene gets
  // everything copied; an arena that outgrew its buffer moves to a larger one on the GPU (the old
  // buffer is retired until this submission has completed), so only the changed chunks travel.
  // Every replaced buffer goes to retired_ (a frame may still read it), which is reserved for all
  // four, so the copies recorded out of them name buffers that do not move.
  retired_.clear();
  retired_.reserve(4);
  std::vector<std::pair<Buffer*, Buffer*>> grown;  // (the larger buffer, the old one in retired_)
  auto ensure = [&](Buffer& b, std::size_t bytes, bool keep) {
    bytes = std::max<std::size_t>(bytes, 16);
    if (b.handle() != VK_NULL_HANDLE && b.size() >= bytes) return;
    Buffer bigger(ctx_, bytes, kSceneBufferUsage, false);
    const bool had = b.handle() != VK_NULL_HANDLE;
    if (had) retired_.push_back(std::move(b));
    if (keep && !whole && had)
      grown.emplace_back(&b, &retired_.back());
    else
      whole = true;
    b = std::move(bigger);
    frames_.buffers_replaced();
  };
  ensure(info_, chunks * 16, false);
  ensure(palette_, 256 * 16, false);
  ensure(skip_, skip_bytes(s), true);
  ensure(light_, light_bytes(s), true);
  if (whole) grown.clear();  // everything is copied from the host anyway
  // The recorder orders these copies after the frames submitted earlier that read the buffers
  // they write (an application that records frames into its own command buffers need not wait
  // for one before syncing), and the moved contents before the changed chunks written over them.
  for (auto& [now, old] : grown) rec.copy(*old, 0, *now, 0, old->size());

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

Image render(Context& context, const RenderScene& scene, const Camera& camera,
             const RenderOptions& o, RenderStats* stats, std::vector<PassTiming>* timings) {
  ResidentScene resident(context);
  const FrameScene f = resident.frame_scene(scene.impl());
  check_frame(f, o);
  return render_and_read(
      context.impl(), resident.frames(), f,
      [&](Recorder& rec) { resident.record_sync(rec, scene); }, camera, o, stats, timings);
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
  Recorder rec(impl_->context->impl(), &impl_->resident.frames().sets());
  impl_->resident.record_sync(rec, scene);
  rec.submit();
  return true;
}

Image SceneRenderer::render(const Camera& camera, const RenderOptions& options, RenderStats* stats,
                            std::vector<PassTiming>* timings) {
  ResidentScene& r = impl_->resident;
  if (!r.scene()) throw InvalidArgument("GPU render: no scene synced yet");
  return render_and_read(impl_->context->impl(), r.frames(), r.frame_scene(*r.scene()), nullptr,
                         camera, options, stats, timings);
}

Context& SceneRenderer::context() {
  return *impl_->context;
}

VkBuffer record_render(SceneRenderer& renderer, VkCommandBuffer cmd, const Camera& camera,
                       const RenderOptions& options, PixelOrder order) {
  ResidentScene& r = renderer.impl().resident;
  if (!r.scene()) throw InvalidArgument("GPU render: no scene synced yet");
  const FrameScene f = r.frame_scene(*r.scene());
  check_frame(f, options);  // before computing an approximation for a frame refused
  r.frames().prepare_approximation(f, options);
  Recorder rec(renderer.context().impl(), cmd, r.frames().sets());
  r.frames().record_render(rec, f, camera, options, order == PixelOrder::kBgra, /*timed=*/false);
  // The application copies the pixels out with a transfer.
  rec.expose(r.frames().pixels(), VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  return r.frames().pixels().handle();
}

}  // namespace voxfield::gpu
