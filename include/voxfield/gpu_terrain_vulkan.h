// voxfield — the terrain renderer's frame recorded into an application's own command buffer (on a
// device handed over with gpu::adopt, gpu_vulkan.h). Includes the Vulkan headers for the handle
// types only.
#pragma once

#include "voxfield/gpu_terrain.h"
#include "voxfield/gpu_vulkan.h"

namespace voxfield::gpu {

// Records a frame of `renderer`'s synced terrain into `cmd` (on the adopted queue's family): the
// classify pass, the HistoPyramid, the draw's arguments, the indirect draw, and the copy of the
// pixels into a buffer it returns — width x height packed 8-bit pixels in `order` (alpha 255),
// top row first, readable by transfers: ready for vkCmdCopyBufferToImage into a UNORM swapchain
// image. Record it outside a render pass instance (it records copies, barriers and its own render
// pass). The buffer, the images and the frame's parameters are reused by the next frame: wait for
// `cmd` before recording another. A sync that uploads rows (after edits) may run while the frame
// executes (its copies are ordered after it on the queue) or between recording and submitting it
// (the frame begins with a barrier on everything submitted before it); a sync that copies the
// whole field (the first, or a terrain of another shape) replaces the buffers the frame names, so
// it must not run between recording a frame and submitting it. TerrainRenderer::last_triangles()
// reads the count this frame drew once it has completed. Throws as TerrainRenderer::render.
VkBuffer record_render(TerrainRenderer& renderer, VkCommandBuffer cmd, const TerrainView& view,
                       PixelOrder order);

}  // namespace voxfield::gpu
