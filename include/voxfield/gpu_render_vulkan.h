// voxfield — the ray marcher recorded into an application's own command buffer (on a device
// handed over with gpu::adopt, gpu_vulkan.h). Includes the Vulkan headers for the handle types
// only.
#pragma once

#include "voxfield/gpu_render.h"
#include "voxfield/gpu_vulkan.h"

namespace voxfield::gpu {

// Records a frame of `renderer`'s synced scene into the application's command buffer `cmd` (on
// the adopted queue's family): frame parameters, the ray-marching dispatch, and a barrier that
// makes the pixels readable by transfers. Returns the buffer holding them: width x height packed
// 8-bit pixels in `order` (sRGB-encoded, alpha 255), top row first — ready for
// vkCmdCopyBufferToImage into a UNORM swapchain image. The buffer and the frame's parameters are
// reused by the next frame: wait for `cmd` before recording another frame. SceneRenderer::sync()
// may run while the frame executes (its copies wait for it on the queue; buffers it replaces live
// until the sync after), or between recording the frame and submitting it: the frame begins with a
// barrier on everything submitted before it on the queue. An error view whose approximation is
// not resident computes it first, on the adopted queue with a submit and a fence wait of its own
// (gpu_render.h): do not use that queue from another thread meanwhile. Its copy to the frame's
// buffers is recorded into `cmd` and is taken as done from then on: submit every frame recorded.
// Throws InvalidArgument as SceneRenderer::render does.
VkBuffer record_render(SceneRenderer& renderer, VkCommandBuffer cmd, const Camera& camera,
                       const RenderOptions& options, PixelOrder order);
// The same for a scene packed on the device (DeviceRenderScene): update() may run between frames,
// not while one executes (it submits and waits on the adopted queue).
VkBuffer record_render(DeviceRenderScene& scene, VkCommandBuffer cmd, const Camera& camera,
                       const RenderOptions& options, PixelOrder order);

}  // namespace voxfield::gpu
