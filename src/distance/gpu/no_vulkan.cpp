// voxfield — the distance module's GPU entry points in a build without the Vulkan backend: each
// reports GpuUnavailable (the CPU half, distance.h, is always there).
#include "gpu/unavailable.h"
#include "voxfield/gpu_distance.h"

namespace voxfield::gpu {

DistanceField compute_distance_field(Context&, const World&, const DistanceOptions&,
                                     std::vector<PassTiming>*) {
  built_without_vulkan();
}

DistanceField compute_distance_field(Context&, const World&, const DistanceOptions&,
                                     const AlgorithmOptions&, AlgorithmStats*,
                                     std::vector<PassTiming>*) {
  built_without_vulkan();
}

DistanceField compute_slab_distance_field(Context&, const World&, const DistanceOptions&,
                                          std::int32_t, std::int32_t, const SlabNeighbours&,
                                          std::vector<PassTiming>*) {
  built_without_vulkan();
}

class FieldEngine {};
DynamicField::DynamicField(std::shared_ptr<Context>, const World&, DistanceOptions) {
  built_without_vulkan();
}
DynamicField::DynamicField(DynamicField&, DistanceOptions) {
  built_without_vulkan();
}
DynamicField::~DynamicField() = default;
void DynamicField::rebuild() {
  built_without_vulkan();
}
DynamicDistanceField::UpdateStats DynamicField::update(const DirtyRegions&) {
  built_without_vulkan();
}
DistanceField DynamicField::download() {
  built_without_vulkan();
}
const DistanceOptions& DynamicField::options() const {
  built_without_vulkan();
}
std::size_t DynamicField::field_bytes() const {
  built_without_vulkan();
}
std::size_t DynamicField::last_upload_bytes() const {
  built_without_vulkan();
}
ResidentField DynamicField::resident() {
  built_without_vulkan();
}

}  // namespace voxfield::gpu
