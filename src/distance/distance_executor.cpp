// voxfield — the distance module's one API over both backends (distance_executor.h): each call
// goes to the CPU half or the Vulkan half as the executor says.
#include "voxfield/distance_executor.h"

#include <variant>

namespace voxfield {

DistanceField compute_distance_field(const Executor& executor, const World& world,
                                     const DistanceOptions& options,
                                     const AlgorithmOptions& algorithm, AlgorithmStats* stats) {
  if (executor.on_gpu())
    return gpu::compute_distance_field(*executor.device(), world, options, algorithm, stats);
  return compute_distance_field(world, options, algorithm, stats);
}

DistanceField compute_slab_distance_field(const Executor& executor, const World& world,
                                          const DistanceOptions& options, std::int32_t z0,
                                          std::int32_t z1, const SlabNeighbours& neighbours) {
  if (executor.on_gpu())
    return gpu::compute_slab_distance_field(*executor.device(), world, options, z0, z1, neighbours);
  return compute_slab_distance_field(world.voxels, options, z0, z1, neighbours);
}

IncrementalDistanceField::IncrementalDistanceField(const Executor& executor, const World& world,
                                                   DistanceOptions options)
    : executor_(executor) {
  if (executor_.on_gpu())
    gpu_ =
        std::make_unique<gpu::DynamicField>(executor_.shared_device(), world, std::move(options));
  else
    cpu_.emplace(world, std::move(options));
}

DynamicDistanceField::UpdateStats IncrementalDistanceField::update(const DirtyRegions& dirty) {
  downloaded_.reset();
  return gpu_ ? gpu_->update(dirty) : cpu_->update(dirty);
}

void IncrementalDistanceField::rebuild() {
  downloaded_.reset();
  if (gpu_)
    gpu_->rebuild();
  else
    cpu_->rebuild();
}

const DistanceField& IncrementalDistanceField::field() {
  if (cpu_) return cpu_->field();
  if (!downloaded_) downloaded_ = gpu_->download();
  return *downloaded_;
}

const DistanceOptions& IncrementalDistanceField::options() const {
  return gpu_ ? gpu_->options() : cpu_->options();
}

Vec3i IncrementalDistanceField::reach() const {
  return gpu_ ? gpu_->reach() : cpu_->reach();
}

std::size_t IncrementalDistanceField::memory_bytes() const {
  if (gpu_) return gpu_->field_bytes();
  return std::visit([](const auto& g) { return g.memory().bytes; }, cpu_->field().values);
}

}  // namespace voxfield
