// voxfield — the vector-field module's GPU entry points in a build without the Vulkan backend:
// each reports GpuUnavailable (the CPU half, vectors.h, is always there).
#include "gpu/unavailable.h"
#include "voxfield/gpu_vectors.h"

namespace voxfield::gpu {

bool supports_vector_passes(Context&, std::string* why) {
  if (why) *why = "this voxfield was built without the Vulkan backend";
  return false;
}

VectorTexture generate_vectors(Context&, const VectorVolume&, std::span<const VectorSource>,
                               VectorStorage, const VectorOptions&, std::vector<std::int32_t>*,
                               VectorGpuStats*, std::vector<PassTiming>*) {
  built_without_vulkan();
}

Image render_vectors(Context&, const VectorVolume&, const VectorTexture&, const VectorViewOptions&,
                     VectorGpuStats*) {
  built_without_vulkan();
}

struct VectorSimulation::Impl {};
VectorSimulation::VectorSimulation(std::shared_ptr<Context>, const VectorVolume&, VectorStorage,
                                   VectorOptions, double) {
  built_without_vulkan();
}
VectorSimulation::~VectorSimulation() = default;
void VectorSimulation::step(std::span<const VectorSource>, double) {
  built_without_vulkan();
}
VectorTexture VectorSimulation::field() {
  built_without_vulkan();
}
VectorTexture VectorSimulation::current() {
  built_without_vulkan();
}
Image VectorSimulation::render(const VectorViewOptions&) {
  built_without_vulkan();
}
const VectorVolume& VectorSimulation::volume() const {
  built_without_vulkan();
}
VectorStorage VectorSimulation::storage() const {
  built_without_vulkan();
}
std::int64_t VectorSimulation::steps() const {
  built_without_vulkan();
}
const VectorGpuStats& VectorSimulation::last_stats() const {
  built_without_vulkan();
}
const std::vector<PassTiming>& VectorSimulation::last_timings() const {
  built_without_vulkan();
}
Context& VectorSimulation::context() {
  built_without_vulkan();
}

}  // namespace voxfield::gpu
