// voxfield — the render module's GPU entry points in a build without the Vulkan backend: each
// reports GpuUnavailable (the CPU renderer, render.h, is always there).
#include "gpu/unavailable.h"
#include "voxfield/gpu_render.h"

namespace voxfield::gpu {

Image render(Context&, const RenderScene&, const Camera&, const RenderOptions&, RenderStats*,
             std::vector<PassTiming>*) {
  built_without_vulkan();
}

struct SceneRenderer::Impl {};
SceneRenderer::SceneRenderer(std::shared_ptr<Context>) {
  built_without_vulkan();
}
SceneRenderer::~SceneRenderer() = default;
bool SceneRenderer::sync(const RenderScene&) {
  built_without_vulkan();
}
Image SceneRenderer::render(const Camera&, const RenderOptions&, RenderStats*,
                            std::vector<PassTiming>*) {
  built_without_vulkan();
}
Context& SceneRenderer::context() {
  built_without_vulkan();
}

Image render_csg(Context&, const csg::Model&, const CsgRenderOptions&, CsgRenderStats*,
                 const CsgGpuOptions&, CsgGpuStats*) {
  built_without_vulkan();
}

}  // namespace voxfield::gpu
