// voxfield CLI — choosing the backend a command runs on (said on stderr), and what the device did,
// for stats files.
#pragma once

#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "voxfield/gpu.h"

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

// The executor a command runs on (the same choice, said the same way).
inline Executor choose_executor(const std::string& name) {
  return Executor(choose_backend(name));
}

// What the device did so far, or null on the CPU.
inline nlohmann::json gpu_json(const Executor& executor) {
  return executor.on_gpu() ? gpu_json(*executor.device()) : nlohmann::json(nullptr);
}
inline gpu::Counters gpu_counters(const Executor& executor) {
  return executor.on_gpu() ? executor.device()->counters() : gpu::Counters{};
}

}  // namespace voxfield::cli
