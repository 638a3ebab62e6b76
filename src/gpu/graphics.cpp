// voxfield GPU compute layer — render targets, graphics kernels, and the recorder's draws (see
// graphics.h).
#include "gpu/graphics.h"

#include <string>
#include <utility>

#include "gpu/recorder.h"
#include "voxfield/error.h"

namespace voxfield::gpu {

namespace {

constexpr VkShaderStageFlags kDrawStages =
    VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// The depth format: 32-bit float where the device can attach it (reversed depth keeps its
// precision far away), else 24-bit or 16-bit fixed point (Vulkan guarantees 16-bit and one of
// the other two).
VkFormat depth_format(const Context::Impl& ctx) {
  for (VkFormat f : {VK_FORMAT_D32_SFLOAT, VK_FORMAT_X8_D24_UNORM_PACK32, VK_FORMAT_D16_UNORM}) {
    VkFormatProperties props;
    vkGetPhysicalDeviceFormatProperties(ctx.physical, f, &props);
    if (props.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) return f;
  }
  return VK_FORMAT_D16_UNORM;
}

}  // namespace

RenderTarget::RenderTarget(Context::Impl& ctx, int width, int height, VkFormat colour)
    : ctx_(ctx), width_(width), height_(height), format_(colour) {
  if (width < 1 || height < 1 ||
      static_cast<std::uint32_t>(width) > ctx.limits.maxFramebufferWidth ||
      static_cast<std::uint32_t>(height) > ctx.limits.maxFramebufferHeight)
    throw InvalidArgument("GPU render target: " + std::to_string(width) + " x " +
                          std::to_string(height) + " pixels is outside 1.." +
                          std::to_string(ctx.limits.maxFramebufferWidth) + " x 1.." +
                          std::to_string(ctx.limits.maxFramebufferHeight));
  if (colour != VK_FORMAT_R8G8B8A8_UNORM && colour != VK_FORMAT_B8G8R8A8_UNORM)
    throw InvalidArgument("GPU render target: the colour must be 8-bit UNORM RGBA or BGRA");
  // A partly built target is released by the destructor of a fully constructed one only: build
  // into this object, and on a throw undo here.
  try {
    const VkFormat depth = depth_format(ctx);
    const VkFormat formats[2] = {colour, depth};
    const VkImageUsageFlags usage[2] = {
        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
        VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT};
    const VkImageAspectFlags aspect[2] = {VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_ASPECT_DEPTH_BIT};
    for (int i = 0; i < 2; ++i) {
      VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
      info.imageType = VK_IMAGE_TYPE_2D;
      info.format = formats[i];
      info.extent = {static_cast<std::uint32_t>(width), static_cast<std::uint32_t>(height), 1};
      info.mipLevels = 1;
      info.arrayLayers = 1;
      info.samples = VK_SAMPLE_COUNT_1_BIT;
      info.tiling = VK_IMAGE_TILING_OPTIMAL;
      info.usage = usage[i];
      info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
      info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
      check(vkCreateImage(ctx.device, &info, nullptr, &images_[i]), "vkCreateImage");
      VkMemoryRequirements req;
      vkGetImageMemoryRequirements(ctx.device, images_[i], &req);
      VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
      alloc.allocationSize = req.size;
      alloc.memoryTypeIndex =
          ctx.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
      check(vkAllocateMemory(ctx.device, &alloc, nullptr, &memory_[i]), "vkAllocateMemory (image)");
      check(vkBindImageMemory(ctx.device, images_[i], memory_[i], 0), "vkBindImageMemory");
      VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
      view.image = images_[i];
      view.viewType = VK_IMAGE_VIEW_TYPE_2D;
      view.format = formats[i];
      view.subresourceRange = {aspect[i], 0, 1, 0, 1};
      check(vkCreateImageView(ctx.device, &view, nullptr, &views_[i]), "vkCreateImageView");
    }

    VkAttachmentDescription attachments[2]{};
    attachments[0].format = colour;
    attachments[0].samples = VK_SAMPLE_COUNT_1_BIT;
    attachments[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    attachments[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    attachments[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    attachments[1] = attachments[0];
    attachments[1].format = depth;
    attachments[1].storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    attachments[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    const VkAttachmentReference colour_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    const VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription subpass{};
    subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    subpass.colorAttachmentCount = 1;
    subpass.pColorAttachments = &colour_ref;
    subpass.pDepthStencilAttachment = &depth_ref;
    VkSubpassDependency deps[2]{};
    // In: the clear (and the layout transitions) after the previous frame's depth tests and
    // writes, and after the copy that read its colour.
    deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    deps[0].dstSubpass = 0;
    deps[0].srcStageMask =
        VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
        VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    deps[0].srcAccessMask =
        VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    deps[0].dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT |
                           VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                           VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    deps[0].dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                            VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                            VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    // Out: the colour, in TRANSFER_SRC_OPTIMAL, to the copy that reads it.
    deps[1].srcSubpass = 0;
    deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    deps[1].srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    deps[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rp.attachmentCount = 2;
    rp.pAttachments = attachments;
    rp.subpassCount = 1;
    rp.pSubpasses = &subpass;
    rp.dependencyCount = 2;
    rp.pDependencies = deps;
    check(vkCreateRenderPass(ctx.device, &rp, nullptr, &render_pass_), "vkCreateRenderPass");
    VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = render_pass_;
    fb.attachmentCount = 2;
    fb.pAttachments = views_.data();
    fb.width = static_cast<std::uint32_t>(width);
    fb.height = static_cast<std::uint32_t>(height);
    fb.layers = 1;
    check(vkCreateFramebuffer(ctx.device, &fb, nullptr, &framebuffer_), "vkCreateFramebuffer");
  } catch (...) {
    release();
    throw;
  }
}

RenderTarget::~RenderTarget() {
  release();
}

void RenderTarget::release() {
  const VkDevice d = ctx_.device;
  if (framebuffer_) vkDestroyFramebuffer(d, framebuffer_, nullptr);
  if (render_pass_) vkDestroyRenderPass(d, render_pass_, nullptr);
  for (int i = 0; i < 2; ++i) {
    if (views_[i]) vkDestroyImageView(d, views_[i], nullptr);
    if (images_[i]) vkDestroyImage(d, images_[i], nullptr);
    if (memory_[i]) vkFreeMemory(d, memory_[i], nullptr);
  }
  framebuffer_ = VK_NULL_HANDLE;
  render_pass_ = VK_NULL_HANDLE;
  views_ = {};
  images_ = {};
  memory_ = {};
}

GraphicsKernel::GraphicsKernel(Context::Impl& ctx, const ShaderSource& vertex,
                               const ShaderSource& fragment, const RenderTarget& target)
    : ctx_(ctx), format_(target.format()) {
  kernel_.name = std::string(vertex.name) + "+" + fragment.name;
  const ShaderInterface v = reflect(vertex.name, vertex.spirv, VK_SHADER_STAGE_VERTEX_BIT);
  const ShaderInterface f = reflect(fragment.name, fragment.spirv, VK_SHADER_STAGE_FRAGMENT_BIT);
  ShaderInterface& in = kernel_.interface;
  in.buffers = v.buffers;
  if (f.buffers.size() > in.buffers.size()) in.buffers.resize(f.buffers.size(), Access::kNone);
  for (std::size_t b = 0; b < f.buffers.size(); ++b)
    in.buffers[b] =
        static_cast<Access>(static_cast<int>(in.buffers[b]) | static_cast<int>(f.buffers[b]));
  if (v.push_bytes != 0 && f.push_bytes != 0 && v.push_bytes != f.push_bytes)
    throw InvalidArgument("GPU graphics kernel " + kernel_.name +
                          ": the two stages declare push-constant blocks of different sizes");
  in.push_bytes = std::max(v.push_bytes, f.push_bytes);

  const VkDevice d = ctx.device;
  VkShaderModule modules[2] = {VK_NULL_HANDLE, VK_NULL_HANDLE};
  try {
    make_layouts(d, kernel_, kDrawStages);

    const ShaderSource* sources[2] = {&vertex, &fragment};
    VkPipelineShaderStageCreateInfo stages[2]{};
    for (int i = 0; i < 2; ++i) {
      VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
      sm.codeSize = sources[i]->spirv.size_bytes();
      sm.pCode = sources[i]->spirv.data();
      check(vkCreateShaderModule(d, &sm, nullptr, &modules[i]), "vkCreateShaderModule");
      stages[i].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
      stages[i].stage = i == 0 ? VK_SHADER_STAGE_VERTEX_BIT : VK_SHADER_STAGE_FRAGMENT_BIT;
      stages[i].module = modules[i];
      stages[i].pName = "main";
    }
    VkPipelineVertexInputStateCreateInfo input{
        VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo assembly{
        VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo viewport{
        VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo raster{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1;
    VkPipelineMultisampleStateCreateInfo multisample{
        VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo depth{
        VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    depth.depthTestEnable = VK_TRUE;
    depth.depthWriteEnable = VK_TRUE;
    depth.depthCompareOp = VK_COMPARE_OP_GREATER;  // reversed depth
    VkPipelineColorBlendAttachmentState blend{};
    blend.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                           VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    VkPipelineColorBlendStateCreateInfo colour{
        VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    colour.attachmentCount = 1;
    colour.pAttachments = &blend;
    const VkDynamicState dynamic_states[2] = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dynamic.dynamicStateCount = 2;
    dynamic.pDynamicStates = dynamic_states;
    VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    info.stageCount = 2;
    info.pStages = stages;
    info.pVertexInputState = &input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &colour;
    info.pDynamicState = &dynamic;
    info.layout = kernel_.layout;
    info.renderPass = target.render_pass();
    info.subpass = 0;
    check(vkCreateGraphicsPipelines(d, VK_NULL_HANDLE, 1, &info, nullptr, &kernel_.pipeline),
          ("vkCreateGraphicsPipelines (" + kernel_.name + ")").c_str());
  } catch (...) {
    for (VkShaderModule m : modules)
      if (m) vkDestroyShaderModule(d, m, nullptr);
    release();
    throw;
  }
  for (VkShaderModule m : modules) vkDestroyShaderModule(d, m, nullptr);
}

GraphicsKernel::~GraphicsKernel() {
  release();
}

void GraphicsKernel::release() {
  const VkDevice d = ctx_.device;
  if (kernel_.pipeline) vkDestroyPipeline(d, kernel_.pipeline, nullptr);
  if (kernel_.layout) vkDestroyPipelineLayout(d, kernel_.layout, nullptr);
  if (kernel_.set_layout) vkDestroyDescriptorSetLayout(d, kernel_.set_layout, nullptr);
  kernel_.pipeline = VK_NULL_HANDLE;
  kernel_.layout = VK_NULL_HANDLE;
  kernel_.set_layout = VK_NULL_HANDLE;
}

// ---- the recorder's draws (recorder.h) ---------------------------------------------------------

void Recorder::draw_indirect(const GraphicsKernel& graphics, RenderTarget& target, Buffers buffers,
                             const void* push, std::size_t push_bytes, Buffer& args,
                             VkDeviceSize offset, const std::array<float, 4>& clear) {
  if (graphics.format() != target.format())
    throw InvalidArgument("GPU graphics kernel " + graphics.kernel().name +
                          ": made for another colour format than the target's");
  const Use use{&args, VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT, VK_ACCESS_INDIRECT_COMMAND_READ_BIT};
  bind(graphics.kernel(), buffers, push, push_bytes, &use, VK_PIPELINE_BIND_POINT_GRAPHICS);
  VkClearValue clears[2];
  clears[0].color = {{clear[0], clear[1], clear[2], clear[3]}};
  clears[1].depthStencil = {0.0f, 0};  // reversed depth: 0 is infinitely far
  VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  begin.renderPass = target.render_pass();
  begin.framebuffer = target.framebuffer();
  begin.renderArea.extent = {static_cast<std::uint32_t>(target.width()),
                             static_cast<std::uint32_t>(target.height())};
  begin.clearValueCount = 2;
  begin.pClearValues = clears;
  vkCmdBeginRenderPass(cmd_, &begin, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{
      0, 0, static_cast<float>(target.width()), static_cast<float>(target.height()), 0, 1};
  vkCmdSetViewport(cmd_, 0, 1, &viewport);
  vkCmdSetScissor(cmd_, 0, 1, &begin.renderArea);
  vkCmdDrawIndirect(cmd_, args.handle(), offset, 1, 0);
  vkCmdEndRenderPass(cmd_);
  ++ctx_.counters.draws;
}

void Recorder::copy_colour(RenderTarget& target, Buffer& dst) {
  const VkDeviceSize bytes =
      4ull * static_cast<VkDeviceSize>(target.width()) * static_cast<VkDeviceSize>(target.height());
  if (dst.size() < bytes)
    throw InvalidArgument("GPU recorder: the colour copy needs " + std::to_string(bytes) +
                          " bytes; the buffer has " + std::to_string(dst.size()));
  const Use use{&dst, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT};
  prepare({&use, 1});  // the image's own dependency is the render pass's outgoing one
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {static_cast<std::uint32_t>(target.width()),
                        static_cast<std::uint32_t>(target.height()), 1};
  vkCmdCopyImageToBuffer(cmd_, target.colour(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, dst.handle(),
                         1, &region);
  if (dst.mapped()) ctx_.counters.bytes_downloaded += static_cast<std::int64_t>(bytes);
}

}  // namespace voxfield::gpu
