// voxfield benchmarks — what the GPU bench programs share.
#pragma once

#include <cstdio>
#include <memory>

#include "voxfield/error.h"
#include "voxfield/gpu.h"

namespace voxfield::bench {

// A Vulkan device for a GPU benchmark, a software one (lavapipe) too; null, after saying why on
// stderr as `program`, when there is none.
inline std::shared_ptr<gpu::Context> vulkan_device(const char* program) {
  try {
    gpu::ContextOptions co;
    co.allow_software = true;
    return gpu::Context::create(co);
  } catch (const Error& e) {
    std::fprintf(stderr, "%s: no Vulkan device: %s\n", program, e.what());
    return nullptr;
  }
}

}  // namespace voxfield::bench
