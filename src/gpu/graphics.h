// voxfield GPU compute layer — graphics: a render target (a colour and a depth image with their
// render pass) and graphics kernels (a vertex and a fragment shader that pull what they draw from
// storage buffers: no vertex input, no vertex buffer), recorded by the Recorder like dispatches,
// with the buffers' barriers derived the same way (recorder.h).
//
// The images' own synchronisation lives in the render pass: its attachments start UNDEFINED
// (every draw pass clears them), an incoming dependency orders the clear after the previous
// frame's depth writes and after the copy that read the previous colour, and the colour ends in
// TRANSFER_SRC_OPTIMAL with an outgoing dependency to the copy that reads it
// (Recorder::copy_colour). So a target needs no barrier by hand, frame after frame.
#pragma once

#include <volk.h>

#include <array>
#include <memory>

#include "gpu/kernel.h"
#include "gpu/vulkan_context.h"

namespace voxfield::gpu {

class RenderTarget {
 public:
  // width x height pixels of `colour` (an 8-bit UNORM RGBA or BGRA format) and a depth (32-bit
  // float where the device attaches it, else 24- or 16-bit fixed point). Throws InvalidArgument for
  // a size past the device's framebuffer limits, and what check() throws when Vulkan refuses.
  RenderTarget(Context::Impl& ctx, int width, int height, VkFormat colour);
  ~RenderTarget();
  RenderTarget(const RenderTarget&) = delete;
  RenderTarget& operator=(const RenderTarget&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  VkFormat format() const { return format_; }
  VkRenderPass render_pass() const { return render_pass_; }
  VkFramebuffer framebuffer() const { return framebuffer_; }
  VkImage colour() const { return images_[0]; }

 private:
  void release();
  Context::Impl& ctx_;
  int width_, height_;
  VkFormat format_;
  std::array<VkImage, 2> images_{};  // colour, depth
  std::array<VkDeviceMemory, 2> memory_{};
  std::array<VkImageView, 2> views_{};
  VkRenderPass render_pass_ = VK_NULL_HANDLE;
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
};

// A vertex and a fragment shader as one pipeline for a target's render pass: set-0 storage
// buffers (the union of both stages' bindings, visible to both), one push-constant block shared
// by both stages, triangle lists, depth test and write with reversed depth (greater is nearer;
// targets clear depth to 0), no culling (the fragment shader lights both faces). The viewport is
// the target's, set when the draw is recorded.
class GraphicsKernel {
 public:
  GraphicsKernel(Context::Impl& ctx, const ShaderSource& vertex, const ShaderSource& fragment,
                 const RenderTarget& target);
  ~GraphicsKernel();
  GraphicsKernel(const GraphicsKernel&) = delete;
  GraphicsKernel& operator=(const GraphicsKernel&) = delete;

  // Its descriptor layout, pipeline layout and pipeline, as a Kernel for the descriptor arena.
  const Kernel& kernel() const { return kernel_; }
  VkFormat format() const { return format_; }

 private:
  void release();
  Context::Impl& ctx_;
  Kernel kernel_;
  VkFormat format_;
};

}  // namespace voxfield::gpu
