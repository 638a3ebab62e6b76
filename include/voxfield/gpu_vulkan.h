// voxfield — handing voxfield an application's own Vulkan device (the demo, an engine): the GPU
// compute layer's side; recording frames into the application's command buffers is in
// gpu_render_vulkan.h. Includes the Vulkan headers for the handle types only; voxfield calls
// Vulkan through its own loader table.
#pragma once

#ifndef VK_NO_PROTOTYPES
#define VK_NO_PROTOTYPES
#endif
#include <vulkan/vulkan_core.h>

#include <cstdint>
#include <memory>

#include "voxfield/gpu.h"

namespace voxfield::gpu {

struct AdoptedDevice {
  VkInstance instance = VK_NULL_HANDLE;  // created with Vulkan 1.1 or later
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;  // a queue of `queue_family`, which must support compute
  std::uint32_t queue_family = 0;
  // Whether the device was created with the shaderFloat64 feature enabled: the vector-field
  // passes need it (gpu_vectors.h); everything else runs without it.
  bool shader_float64 = false;
  // ContextOptions::max_storage_buffer_bytes (gpu.h): 0, the device's own range.
  std::uint64_t max_storage_buffer_bytes = 0;
};

// A context on the application's device and queue: voxfield creates its command pool, pipelines
// and buffers there and destroys only those; the application keeps its handles alive longer than
// the context and does not use the queue from another thread while voxfield submits to it.
// Throws InvalidArgument for missing handles, GpuUnavailable when the queue cannot compute.
std::shared_ptr<Context> adopt(const AdoptedDevice& device);

// Byte order of the packed 32-bit pixels voxfield records into an application's frame (the ray
// marcher's, gpu_render_vulkan.h; the vector-field visualiser's, gpu_vectors_vulkan.h).
enum class PixelOrder { kRgba, kBgra };

}  // namespace voxfield::gpu
