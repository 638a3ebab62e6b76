// voxfield — handing voxfield an application's own Vulkan device (the demo, an engine). Includes
// the Vulkan headers for the handle types only; voxfield calls Vulkan through its own loader table.
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
  VkQueue queue = VK_NULL_HANDLE;        // a queue of `queue_family`, which must support compute
  std::uint32_t queue_family = 0;
};

// A context on the application's device and queue: voxfield creates its command pool, pipelines
// and buffers there and destroys only those; the application keeps its handles alive longer than
// the context and does not use the queue from another thread while voxfield submits to it.
// Throws InvalidArgument for missing handles, GpuUnavailable when the queue cannot compute.
std::shared_ptr<Context> adopt(const AdoptedDevice& device);

enum class PixelOrder { kRgba, kBgra };  // byte order of a packed 32-bit pixel

// Records a frame of `renderer`'s synced scene into the application's command buffer `cmd` (on
// the adopted queue's family): frame parameters, the ray-marching dispatch, and a barrier that
// makes the pixels readable by transfers. Returns the buffer holding them: width x height packed
// 8-bit pixels in `order` (sRGB-encoded, alpha 255), top row first — ready for
// vkCmdCopyBufferToImage into a UNORM swapchain image. The buffer and the frame's parameters are
// reused by the next frame: wait for `cmd` before recording another frame. SceneRenderer::sync()
// may run while the frame executes (its copies wait for it on the queue; buffers it replaces live
// until the sync after).
// Throws InvalidArgument as SceneRenderer::render does.
VkBuffer record_render(SceneRenderer& renderer, VkCommandBuffer cmd, const Camera& camera,
                       const RenderOptions& options, PixelOrder order);

}  // namespace voxfield::gpu
