// voxfield — the render module's GPU half: the ray marcher as a Vulkan compute shader, for one
// frame (gpu::render) or for a scene kept resident across frames (gpu::SceneRenderer). The CPU half
// is render.h. An application's own device and command buffer: gpu_render_vulkan.h.
#pragma once

#include <memory>
#include <vector>

#include "voxfield/gpu.h"
#include "voxfield/render.h"

namespace voxfield::gpu {

// Renders a frame of `scene` with the ray-marching compute shader: the CPU renderer's traversal,
// data and shading, in floats — images match the CPU's within the tolerance tests/test_gpu.cpp
// states. Every view (the error view's counts, rays_through_geometry and max_error, stay zero:
// the CPU renderer reports them). One submit; stats->ms
// covers upload, render and read-back. For many frames of a changing scene, use SceneRenderer.
Image render(Context& context, const RenderScene& scene, const Camera& camera,
             const RenderOptions& options, RenderStats* stats = nullptr,
             std::vector<PassTiming>* timings = nullptr);

// A RenderScene kept on the GPU for many frames — an editor's or a game's view of a changing
// world. The first sync() copies the whole scene; after RenderScene::update() only the chunks it
// re-read (and the palette) are copied, so an edit costs its chunks, not the world. Not
// thread-safe; one frame at a time (a frame's buffers are reused by the next).
class SceneRenderer {
 public:
  explicit SceneRenderer(std::shared_ptr<Context> context);  // InvalidArgument without a context
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Brings the GPU copy up to date with `scene` (another scene than last time is copied whole):
  // one submit and one fence wait when anything changed, none otherwise. Returns whether it copied.
  bool sync(const RenderScene& scene);
  // A frame of the synced scene, read back (as gpu::render; stats->ms covers render + read-back).
  // Throws InvalidArgument before the first sync and for what gpu::render refuses.
  Image render(const Camera& camera, const RenderOptions& options, RenderStats* stats = nullptr,
               std::vector<PassTiming>* timings = nullptr);
  Context& context();

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxfield::gpu
