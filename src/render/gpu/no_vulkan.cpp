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

struct DeviceRenderScene::Impl {};
DeviceRenderScene::DeviceRenderScene(std::shared_ptr<Context>, const World&, RenderSceneOptions,
                                     std::optional<Box3i>) {
  built_without_vulkan();
}
DeviceRenderScene::~DeviceRenderScene() = default;
DeviceRenderScene::UpdateStats DeviceRenderScene::update(const DirtyRegions&) {
  built_without_vulkan();
}
const DeviceRenderScene::UpdateStats& DeviceRenderScene::build_stats() const {
  built_without_vulkan();
}
Image DeviceRenderScene::render(const Camera&, const RenderOptions&, RenderStats*,
                                std::vector<PassTiming>*) {
  built_without_vulkan();
}
const Box3i& DeviceRenderScene::box() const {
  built_without_vulkan();
}
Context& DeviceRenderScene::context() {
  built_without_vulkan();
}

Image render_csg(Context&, const csg::Model&, const CsgRenderOptions&, CsgRenderStats*,
                 const CsgGpuOptions&, CsgGpuStats*) {
  built_without_vulkan();
}

}  // namespace voxfield::gpu
