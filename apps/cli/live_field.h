// voxfield CLI — a distance field that follows edits on the chosen backend (CPU or Vulkan), for
// `edit` and `bench edits`.
#pragma once

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "voxfield/dynamic_field.h"
#include "voxfield/gpu.h"

namespace voxfield::cli {

class LiveField {
 public:
  // backend: "cpu", "vulkan" or "auto". Says on stderr which one runs and why.
  LiveField(const World& world, const DistanceOptions& options, const std::string& backend) {
    std::string why;
    auto ctx = gpu::select_backend(parse_backend(backend), {}, &why);
    std::cerr << "voxfield: " << why << "\n";
    if (ctx) {
      gpu_.emplace(std::move(ctx), world, options);
    } else {
      cpu_.emplace(world, options);
    }
  }

  DynamicDistanceField::UpdateStats update(const DirtyRegions& dirty) {
    downloaded_.reset();
    return cpu_ ? cpu_->update(dirty) : gpu_->update(dirty);
  }

  // The current field (the GPU's is read back once per change).
  const DistanceField& field() {
    if (cpu_) return cpu_->field();
    if (!downloaded_) downloaded_ = gpu_->download();
    return *downloaded_;
  }

  const DistanceOptions& options() const { return cpu_ ? cpu_->options() : gpu_->options(); }
  bool on_gpu() const { return gpu_.has_value(); }

  // What the GPU did so far (null on the CPU): device and hardware-independent counters.
  nlohmann::json gpu_json() {
    if (!gpu_) return nullptr;
    const gpu::Counters c = gpu_->context().counters();
    const gpu::DeviceInfo& d = gpu_->context().device();
    return {{"device", d.name},        {"device_type", d.type},          {"dispatches", c.dispatches},
            {"submits", c.submits},    {"fence_waits", c.fence_waits},   {"pipeline_barriers", c.pipeline_barriers},
            {"bytes_uploaded", c.bytes_uploaded}, {"bytes_downloaded", c.bytes_downloaded}};
  }
  gpu::Counters gpu_counters() { return gpu_ ? gpu_->context().counters() : gpu::Counters{}; }

 private:
  std::optional<DynamicDistanceField> cpu_;
  std::optional<gpu::DynamicField> gpu_;
  std::optional<DistanceField> downloaded_;
};

}  // namespace voxfield::cli
