// voxfield — choosing the CPU or the GPU backend (built with or without Vulkan).
#include "voxfield/gpu.h"

namespace voxfield {

const char* backend_name(Backend b) {
  switch (b) {
    case Backend::kCpu:
      return "cpu";
    case Backend::kVulkan:
      return "vulkan";
    case Backend::kAuto:
      return "auto";
  }
  return "?";
}

Backend parse_backend(const std::string& name) {
  for (Backend b : {Backend::kCpu, Backend::kVulkan, Backend::kAuto})
    if (name == backend_name(b)) return b;
  throw InvalidArgument("unknown backend \"" + name + "\" (expected cpu, vulkan or auto)");
}

namespace gpu {

std::shared_ptr<Context> select_backend(Backend backend, const ContextOptions& options,
                                        std::string* why) {
  auto say = [&](const std::string& s) {
    if (why) *why = s;
  };
  if (backend == Backend::kCpu) {
    say("cpu backend (asked for)");
    return nullptr;
  }
  if (backend == Backend::kVulkan) {
    auto ctx = Context::create(options);  // throws GpuUnavailable with the reason
    say("vulkan backend on " + ctx->device().name + " (" + ctx->device().type + ", Vulkan " +
        ctx->device().api_version_string() + ")");
    return ctx;
  }
  // auto: a hardware GPU, else the CPU.
  ContextOptions hardware = options;
  hardware.allow_software = false;
  try {
    auto ctx = Context::create(hardware);
    say("vulkan backend on " + ctx->device().name + " (" + ctx->device().type + " GPU)");
    return ctx;
  } catch (const GpuUnavailable& e) {
    say(std::string("cpu backend: no hardware GPU (") + e.what() + ")");
    return nullptr;
  }
}

}  // namespace gpu
}  // namespace voxfield
