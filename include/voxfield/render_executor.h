// voxfield — the render module's one API over both backends: frames of a RenderScene drawn where
// an Executor says (gpu.h): the CPU ray marcher (render.h) or the Vulkan compute one
// (gpu_render.h). Images agree within the tolerance tests/test_gpu_render.cpp states; the error
// view's counters are the CPU's alone (gpu_render.h).
#pragma once

#include <memory>
#include <vector>

#include "voxfield/gpu.h"
#include "voxfield/gpu_render.h"
#include "voxfield/render.h"

namespace voxfield {

// One frame of `scene` on `executor` (the whole scene goes to the device each call: for many
// frames, a SceneView). `interrupter` is asked by the CPU renderer between tiles; a device frame
// is one submit and is not interrupted. `timings` receives the device's pass timestamps (empty on
// the CPU). Throws what the chosen backend's renderer throws.
Image render(const Executor& executor, const RenderScene& scene, const Camera& camera,
             const RenderOptions& options, RenderStats* stats = nullptr,
             Interrupter* interrupter = nullptr, std::vector<gpu::PassTiming>* timings = nullptr);

// Frames of a changing scene — an editor's or a game's view — on one executor: on a device the
// scene stays resident and each frame copies only the chunks RenderScene::update() re-read
// (gpu::SceneRenderer); on the CPU each frame reads the scene where it is.
class SceneView {
 public:
  explicit SceneView(Executor executor);
  ~SceneView();
  SceneView(const SceneView&) = delete;
  SceneView& operator=(const SceneView&) = delete;

  // A frame of `scene` as it is now (on a device: synced first, one submit when anything
  // changed). As render() above, except that stats->ms and `timings` cover the frame, not the
  // sync. After a GpuUnavailable of any kind (out of memory included) the device copy may be
  // stale: destroy the view and make a new one.
  Image render(const RenderScene& scene, const Camera& camera, const RenderOptions& options,
               RenderStats* stats = nullptr, Interrupter* interrupter = nullptr,
               std::vector<gpu::PassTiming>* timings = nullptr);
  const Executor& executor() const { return executor_; }

 private:
  Executor executor_;
  std::unique_ptr<gpu::SceneRenderer> device_view_;
};

}  // namespace voxfield
