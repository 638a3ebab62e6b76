// voxfield — the render module's one API over both backends (render_executor.h): each frame goes
// to the CPU ray marcher or the Vulkan one as the executor says.
#include "voxfield/render_executor.h"

namespace voxfield {

Image render(const Executor& executor, const RenderScene& scene, const Camera& camera,
             const RenderOptions& options, RenderStats* stats, Interrupter* interrupter,
             std::vector<gpu::PassTiming>* timings) {
  if (executor.on_gpu())
    return gpu::render(*executor.device(), scene, camera, options, stats, timings);
  if (timings) timings->clear();
  return render(scene, camera, options, stats, interrupter);
}

SceneView::SceneView(Executor executor) : executor_(std::move(executor)) {
  if (executor_.on_gpu())
    device_view_ = std::make_unique<gpu::SceneRenderer>(executor_.shared_device());
}

SceneView::~SceneView() = default;

Image SceneView::render(const RenderScene& scene, const Camera& camera,
                        const RenderOptions& options, RenderStats* stats, Interrupter* interrupter,
                        std::vector<gpu::PassTiming>* timings) {
  if (!device_view_) {
    if (timings) timings->clear();
    return voxfield::render(scene, camera, options, stats, interrupter);
  }
  device_view_->sync(scene);
  return device_view_->render(camera, options, stats, timings);
}

}  // namespace voxfield
