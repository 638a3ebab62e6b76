// voxfield — the GPU entry points of a build without the Vulkan backend (preset cpu-only, or no
// Vulkan headers / glslc at configure time): every call reports GpuUnavailable.
#include "voxfield/gpu.h"

namespace voxfield::gpu {

namespace {
[[noreturn]] void unavailable() {
  throw GpuUnavailable("this voxfield was built without the Vulkan backend (configure with Vulkan headers, "
                       "volk and glslc installed)");
}
}  // namespace

bool built_with_vulkan() { return false; }
std::string DeviceInfo::api_version_string() const { return "0.0.0"; }

struct Context::Impl {};
std::shared_ptr<Context> Context::create(const ContextOptions&) { unavailable(); }
Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::~Context() = default;
const DeviceInfo& Context::device() const { unavailable(); }
Counters Context::counters() const { return {}; }
void Context::reset_counters() {}
std::vector<std::string> Context::validation_messages() const { return {}; }
void Context::clear_validation_messages() {}
bool Context::has_timestamps() const { return false; }

DistanceField compute_distance_field(Context&, const World&, const DistanceOptions&, std::vector<PassTiming>*) {
  unavailable();
}

DistanceField compute_distance_field(Context&, const World&, const DistanceOptions&, const AlgorithmOptions&,
                                     AlgorithmStats*, std::vector<PassTiming>*) {
  unavailable();
}
class FieldEngine {};
Image render(Context&, const RenderScene&, const Camera&, const RenderOptions&, RenderStats*, std::vector<PassTiming>*) {
  unavailable();
}
DynamicField::DynamicField(std::shared_ptr<Context>, const World&, DistanceOptions) { unavailable(); }
DynamicField::~DynamicField() = default;
void DynamicField::rebuild() { unavailable(); }
DynamicDistanceField::UpdateStats DynamicField::update(const DirtyRegions&) { unavailable(); }
DistanceField DynamicField::download() { unavailable(); }
const DistanceOptions& DynamicField::options() const { unavailable(); }
std::size_t DynamicField::field_bytes() const { unavailable(); }
struct SceneRenderer::Impl {};
SceneRenderer::SceneRenderer(std::shared_ptr<Context>) { unavailable(); }
SceneRenderer::~SceneRenderer() = default;
bool SceneRenderer::sync(const RenderScene&) { unavailable(); }
Image SceneRenderer::render(const Camera&, const RenderOptions&, RenderStats*, std::vector<PassTiming>*) { unavailable(); }
Context& SceneRenderer::context() { unavailable(); }

}  // namespace voxfield::gpu
