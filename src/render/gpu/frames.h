// voxfield GPU backend — frames of the ray marcher (shaders/render.comp) over a scene resident on
// the device, wherever its cells were made: copied from a host RenderScene (gpu_render.cpp) or
// packed on the device from fields computed there (device_scene.cpp).
#pragma once

#include <functional>
#include <optional>

#include "../scene_impl.h"
#include "gpu/recorder.h"
#include "voxfield/gpu_render.h"

namespace voxfield::gpu {

// The scene's and the frame's device buffers: bound to shaders, filled and read by copies.
constexpr VkBufferUsageFlags kSceneBufferUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                                 VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                                 VK_BUFFER_USAGE_TRANSFER_SRC_BIT;

// What a frame reads of its scene: the facts the shader's parameters carry and the buffers it
// binds (shaders/layout.h: RenderParams and the chunk table's four words per chunk).
struct FrameScene {
  const World* world = nullptr;  // the error view's approximation is computed from it
  Box3i box;
  render_detail::ChunkTable table;
  std::uint32_t chunk_volume = 0;
  Metric metric = Metric::kManhattan;
  double skip_inv_scale = 1, light_inv_scale = 0.25;
  bool has_light = false;
  DistanceOptions skip_options;          // the skip field's: the approximation's options
  std::uint64_t id = 0, generation = 0;  // the approximation is kept while both hold
  Buffer* info = nullptr;
  Buffer* skip = nullptr;
  Buffer* light = nullptr;
  Buffer* palette = nullptr;
  // The distance view's heat_top: computed on the host (host scenes), or recorded into the
  // frame's parameters buffer by a pass of the caller's after they are written (device scenes).
  std::function<std::uint32_t(int slice_z)> heat_top;
  std::function<void(Recorder&, Buffer& params, int slice_z)> record_heat;
  // The cut of the distance view (throws InvalidArgument outside the box).
  int slice_z(const RenderOptions& o) const;
};

// What a frame checks before anything is recorded (InvalidArgument).
void check_frame(const FrameScene& s, const RenderOptions& o);

// The buffers a frame writes, the error view's approximation, and the descriptor sets, kept
// across frames.
class Frames {
 public:
  // The ray marcher's kernel is made here (on first use in the process), not in the first frame.
  explicit Frames(Context& context);
  Frames(const Frames&) = delete;
  Frames& operator=(const Frames&) = delete;

  // Computes the error view's approximation of `s` when a frame of `o` needs one that is not
  // resident: on the device, by the dissertation's GPU algorithms (gpu_distance.h; brute force,
  // the CPU's reference, on the CPU). Its own submit and fence wait, so it runs before a frame's
  // recording starts (the context's upload buffer may hold that recording's staged copies).
  void prepare_approximation(const FrameScene& s, const RenderOptions& o);
  // Records a frame: parameters and the dispatch.
  void record_render(Recorder& rec, const FrameScene& s, const Camera& camera,
                     const RenderOptions& o, bool bgra, bool timed);

  Buffer& pixels() { return pixels_; }
  DescriptorArena& sets() { return sets_; }
  // The scene's buffers were replaced: the sets that name them go before the next frame (the last
  // frame that used them has completed by then: one frame in flight).
  void buffers_replaced() { descriptors_stale_ = true; }

 private:
  void ensure_pixels(VkDeviceSize bytes);
  // Records the copy of the approximation prepare_approximation() computed, if any (staged in a
  // buffer of its own so a sync in the same command buffer does not overwrite it).
  void record_approximation(Recorder& rec, const FrameScene& s);

  Context& context_;
  Context::Impl& ctx_;
  const Kernel& kernel_;
  Buffer params_, pixels_;
  Buffer approx_info_, approx_arena_, approx_staging_;
  std::optional<SkipSource> approx_computed_;  // prepared, not yet recorded
  std::uint64_t approx_scene_ = 0,
                approx_generation_ = 0;  // what the resident approximation was made from
  int approx_algorithm_ = -1;
  double approx_inv_scale_ = 1;
  DescriptorArena sets_;
  bool descriptors_stale_ = false;
};

// Records the frame, reads it back and converts it to an Image: one submit (and, for an error
// view whose approximation is not resident, the approximation's before it). `record_first`
// records what the frame needs before it (a host scene's copies) into the same command buffer.
Image render_and_read(Context::Impl& ctx, Frames& frames, const FrameScene& s,
                      const std::function<void(Recorder&)>& record_first, const Camera& camera,
                      const RenderOptions& o, RenderStats* stats, std::vector<PassTiming>* timings);

}  // namespace voxfield::gpu
