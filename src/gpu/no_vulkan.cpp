// voxfield — the GPU compute layer of a build without the Vulkan backend (preset cpu-only, or no
// Vulkan headers / glslc at configure time): every call that needs a device reports GpuUnavailable.
#include "unavailable.h"
#include "voxfield/gpu.h"

namespace voxfield::gpu {

void built_without_vulkan() {
  throw GpuUnavailable(
      "this voxfield was built without the Vulkan backend (configure with Vulkan headers, "
      "volk and glslc installed)");
}

bool built_with_vulkan() {
  return false;
}
std::vector<std::uint32_t> compile_compute_shader(std::string_view, std::string_view) {
  built_without_vulkan();
}
std::string DeviceInfo::api_version_string() const {
  return "0.0.0";
}

struct Context::Impl {};
std::shared_ptr<Context> Context::create(const ContextOptions&) {
  built_without_vulkan();
}
Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::~Context() = default;
const DeviceInfo& Context::device() const {
  built_without_vulkan();
}
Counters Context::counters() const {
  return {};
}
void Context::reset_counters() {}
std::vector<std::string> Context::validation_messages() const {
  return {};
}
void Context::clear_validation_messages() {}
bool Context::has_timestamps() const {
  return false;
}
bool Context::lost() const {
  return false;
}

}  // namespace voxfield::gpu
