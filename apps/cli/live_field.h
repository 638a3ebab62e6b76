// voxfield CLI — a distance field that follows edits on the chosen backend (CPU or Vulkan), for
// `edit` and `bench edits`.
#pragma once

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "voxfield/dynamic_field.h"
#include "voxfield/gpu_distance.h"

namespace voxfield::cli {

// The device and the hardware-independent counters of a context, for stats files. Timestamps of a
// software device measure the CPU emulating it: "timings_are" says which.
inline nlohmann::json gpu_json(gpu::Context& ctx) {
  const gpu::Counters c = ctx.counters();
  const gpu::DeviceInfo& d = ctx.device();
  return {{"device", d.name},
          {"device_type", d.type},
          {"timings_are", d.hardware ? "gpu" : "cpu emulation"},
          {"dispatches", c.dispatches},
          {"pipeline_barriers", c.pipeline_barriers},
          {"submits", c.submits},
          {"fence_waits", c.fence_waits},
          {"bytes_uploaded", c.bytes_uploaded},
          {"bytes_downloaded", c.bytes_downloaded},
          {"descriptor_pools", c.descriptor_pools}};
}

inline nlohmann::json pass_timings_json(const std::vector<gpu::PassTiming>& timings) {
  nlohmann::json passes = nlohmann::json::array();
  for (const auto& t : timings) passes.push_back({{"pass", t.pass}, {"ms", t.ms}});
  return passes;
}

// The backend a command runs on, said on stderr. Asking for vulkan where there is no usable
// device is not fatal: the command says why and runs on the CPU.
inline std::shared_ptr<gpu::Context> choose_backend(const std::string& name) {
  std::string why;
  std::shared_ptr<gpu::Context> ctx;
  try {
    ctx = gpu::select_backend(parse_backend(name), {}, &why);
  } catch (const GpuUnavailable& e) {
    why = std::string("no usable Vulkan device (") + e.what() + "); using the cpu backend";
  }
  std::cerr << "voxfield: " << why << "\n";
  return ctx;
}

class LiveField {
 public:
  // backend: "cpu", "vulkan" or "auto". Says on stderr which one runs and why.
  LiveField(const World& world, const DistanceOptions& options, const std::string& backend) {
    auto ctx = choose_backend(backend);
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
  // Bytes the field occupies where it lives: the CPU grid's chunks, or the GPU's resident buffer
  // (packed: 1, 2 or 4 bytes per voxel of the domain) — without reading a GPU field back.
  std::size_t memory_bytes() const {
    if (cpu_)
      return std::visit([](const auto& g) { return g.memory().bytes; }, cpu_->field().values);
    return gpu_->field_bytes();
  }
  bool on_gpu() const { return gpu_.has_value(); }

  // What the GPU did so far (null on the CPU): device and hardware-independent counters.
  nlohmann::json gpu_json() {
    return gpu_ ? voxfield::cli::gpu_json(gpu_->context()) : nlohmann::json(nullptr);
  }
  gpu::Counters gpu_counters() { return gpu_ ? gpu_->context().counters() : gpu::Counters{}; }

 private:
  std::optional<DynamicDistanceField> cpu_;
  std::optional<gpu::DynamicField> gpu_;
  std::optional<DistanceField> downloaded_;
};

}  // namespace voxfield::cli
