// voxfield — vector-field steps and pictures recorded into an application's own command buffers
// (on a device handed over with gpu::adopt, gpu_vulkan.h, created with shaderFloat64): a game
// records the step into its frame, then samples the field buffer from its own shaders through
// voxfield_vectors.glsl. Includes the Vulkan headers for the handle types only.
#pragma once

#include "voxfield/gpu_vectors.h"
#include "voxfield/gpu_vulkan.h"

namespace voxfield::gpu {

// Where a simulation's blended field lives on the device: `bytes` of texels laid out as
// VectorTexture::bytes() (x fastest; rgba8 one word per texel, rgba16f two, rgba32f four), ready
// for a storage-buffer binding or a vkCmdCopyBufferToImage into a 3-D image.
struct VectorFieldBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0, bytes = 0;
};

// Records one step of `sim` (the sources' upload, the passes) into `cmd`, on the adopted queue's
// family, and a barrier that makes the new field readable by the application's compute shaders and
// transfers (and its vertex and fragment shaders where that queue family draws). Returns the buffer
// holding the field after the step. The step's upload and buffers are reused by the next: wait for
// `cmd` before recording or running another step. Throws InvalidArgument as VectorSimulation::step
// does (nothing recorded).
VectorFieldBuffer record_step(VectorSimulation& sim, VkCommandBuffer cmd,
                              std::span<const VectorSource> sources, double dt_s);

// The blended field of the last step (as record_step returned it).
VectorFieldBuffer field_buffer(VectorSimulation& sim);

// Records the visualiser over the simulation's field into `cmd`, and a barrier that makes the
// pixels readable by transfers. Returns the buffer holding width x height packed 8-bit pixels in
// `order` (sRGB-encoded, alpha 255), top row first — ready for vkCmdCopyBufferToImage into a UNORM
// swapchain image. Reused by the next picture: wait for `cmd` first.
VkBuffer record_render(VectorSimulation& sim, VkCommandBuffer cmd, const VectorViewOptions& view,
                       PixelOrder order);

}  // namespace voxfield::gpu
