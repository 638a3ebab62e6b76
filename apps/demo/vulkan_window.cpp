// voxfield-demo — the window, the Vulkan device and the swapchain.
#include "vulkan_window.h"

#include <algorithm>
#include <cstring>
#include <iostream>

namespace voxfield::demo {
namespace {

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS)
    throw WindowError(std::string("Vulkan: ") + what + " failed (VkResult " + std::to_string(r) +
                      ")");
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                             VkDebugUtilsMessageTypeFlagsEXT,
                                             const VkDebugUtilsMessengerCallbackDataEXT* data,
                                             void*) {
  std::cerr << "voxfield-demo: validation: " << data->pMessage << "\n";
  return VK_FALSE;
}

void image_barrier(VkCommandBuffer cmd, VkImage image, VkImageLayout from, VkImageLayout to,
                   VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                   VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
  VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  b.srcAccessMask = src_access;
  b.dstAccessMask = dst_access;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 0, nullptr, 0, nullptr, 1, &b);
}

}  // namespace

VulkanWindow::VulkanWindow(int width, int height, const std::string& title, bool validation) {
  try {
    open(width, height, title, validation);
  } catch (...) {
    release();  // a constructor that throws runs no destructor
    throw;
  }
}

void VulkanWindow::open(int width, int height, const std::string& title, bool validation) {
  if (volkInitialize() != VK_SUCCESS) throw WindowError("no Vulkan loader (install libvulkan1)");
  if (!glfwVulkanSupported()) throw WindowError("GLFW finds no Vulkan support for windows");
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) throw WindowError("GLFW cannot open a window");

  std::uint32_t glfw_count = 0;
  const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
  std::vector<const char*> extensions(glfw_extensions, glfw_extensions + glfw_count);
  std::vector<const char*> layers;
  if (validation) {
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    layers.push_back("VK_LAYER_KHRONOS_validation");
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "voxfield-demo";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  ici.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  // With synchronisation validation too: the demo records voxfield's frame into its own command
  // buffer, then copies it to the swapchain; the layer checks the barriers between the two.
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  if (validation) ici.pNext = &features;
  check(vkCreateInstance(&ici, nullptr, &instance_), "vkCreateInstance");
  volkLoadInstance(instance_);
  if (validation) {
    VkDebugUtilsMessengerCreateInfoEXT m{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    m.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    m.pfnUserCallback = on_validation;
    check(vkCreateDebugUtilsMessengerEXT(instance_, &m, nullptr, &messenger_),
          "vkCreateDebugUtilsMessengerEXT");
  }
  check(glfwCreateWindowSurface(instance_, window_, nullptr, &surface_), "glfwCreateWindowSurface");

  // A device with one queue family that draws, computes and presents to this window; a hardware
  // GPU before a software one.
  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance_, &count, devices.data());
  int best_rank = -1;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    if (p.apiVersion < VK_API_VERSION_1_1) continue;
    std::uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> families(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, families.data());
    for (std::uint32_t f = 0; f < nq; ++f) {
      VkBool32 present = VK_FALSE;
      vkGetPhysicalDeviceSurfaceSupportKHR(d, f, surface_, &present);
      const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
      if (!present || (families[f].queueFlags & need) != need) continue;
      const int rank = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU     ? 3
                       : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 2
                       : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU            ? 0
                                                                                : 1;
      if (rank > best_rank) {
        best_rank = rank;
        physical_ = d;
        family_ = f;
        device_name_ = p.deviceName;
        hardware_ = p.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
      }
      break;
    }
  }
  if (!physical_)
    throw WindowError("no Vulkan device can draw, compute and present to this window");

  const float priority = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  const char* device_extensions[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  // Doubles in shaders where the device has them: voxfield's vector-field passes need them.
  VkPhysicalDeviceFeatures supported{}, enabled{};
  vkGetPhysicalDeviceFeatures(physical_, &supported);
  enabled.shaderFloat64 = supported.shaderFloat64;
  float64_ = supported.shaderFloat64 == VK_TRUE;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.pEnabledFeatures = &enabled;
  dci.enabledExtensionCount = 1;
  dci.ppEnabledExtensionNames = device_extensions;
  check(vkCreateDevice(physical_, &dci, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, family_, 0, &queue_);

  VkCommandPoolCreateInfo cp{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = family_;
  check(vkCreateCommandPool(device_, &cp, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo cba{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cba.commandPool = pool_;
  cba.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cba.commandBufferCount = 1;
  check(vkAllocateCommandBuffers(device_, &cba, &cmd_), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fci.flags = VK_FENCE_CREATE_SIGNALED_BIT;
  check(vkCreateFence(device_, &fci, nullptr, &fence_), "vkCreateFence");
  VkSemaphoreCreateInfo sci{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  check(vkCreateSemaphore(device_, &sci, nullptr, &acquired_), "vkCreateSemaphore");
  create_swapchain();
}

VulkanWindow::~VulkanWindow() {
  release();
}

void VulkanWindow::release() {
  if (device_) {
    vkDeviceWaitIdle(device_);
    destroy_host_buffer(staging_);
    destroy_host_buffer(readback_);
    destroy_swapchain();
    if (render_pass_) vkDestroyRenderPass(device_, render_pass_, nullptr);
    if (acquired_) vkDestroySemaphore(device_, acquired_, nullptr);
    if (fence_) vkDestroyFence(device_, fence_, nullptr);
    if (pool_) vkDestroyCommandPool(device_, pool_, nullptr);
    vkDestroyDevice(device_, nullptr);
  }
  if (surface_) vkDestroySurfaceKHR(instance_, surface_, nullptr);
  if (messenger_) vkDestroyDebugUtilsMessengerEXT(instance_, messenger_, nullptr);
  if (instance_) vkDestroyInstance(instance_, nullptr);
  if (window_) glfwDestroyWindow(window_);
  device_ = VK_NULL_HANDLE;
  surface_ = VK_NULL_HANDLE;
  messenger_ = VK_NULL_HANDLE;
  instance_ = VK_NULL_HANDLE;
  window_ = nullptr;
}

void VulkanWindow::create_swapchain() {
  VkSurfaceCapabilitiesKHR caps;
  check(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical_, surface_, &caps),
        "vkGetPhysicalDeviceSurfaceCapabilitiesKHR");
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw WindowError("the swapchain cannot be written by transfers on this device");
  readable_ = (caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_SRC_BIT) != 0;
  std::uint32_t nf = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &nf, nullptr);
  std::vector<VkSurfaceFormatKHR> formats(nf);
  vkGetPhysicalDeviceSurfaceFormatsKHR(physical_, surface_, &nf, formats.data());
  // UNORM: voxfield's renderers encode sRGB themselves.
  format_ = VK_FORMAT_UNDEFINED;
  VkColorSpaceKHR space = VK_COLOR_SPACE_SRGB_NONLINEAR_KHR;
  for (const VkSurfaceFormatKHR& f : formats)
    if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
      format_ = f.format;
      space = f.colorSpace;
      break;
    }
  if (format_ == VK_FORMAT_UNDEFINED)
    throw WindowError("the window offers no 8-bit RGBA/BGRA UNORM format");

  int fb_w = 0, fb_h = 0;
  glfwGetFramebufferSize(window_, &fb_w, &fb_h);
  if (caps.currentExtent.width != 0xFFFFFFFFu) {
    extent_ = caps.currentExtent;
  } else {
    extent_.width = std::clamp(static_cast<std::uint32_t>(std::max(fb_w, 1)),
                               caps.minImageExtent.width, caps.maxImageExtent.width);
    extent_.height = std::clamp(static_cast<std::uint32_t>(std::max(fb_h, 1)),
                                caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  min_image_count_ = std::max(2u, caps.minImageCount);
  std::uint32_t images = min_image_count_ + 1;
  if (caps.maxImageCount > 0) images = std::min(images, caps.maxImageCount);

  VkSwapchainCreateInfoKHR sci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  sci.surface = surface_;
  sci.minImageCount = images;
  sci.imageFormat = format_;
  sci.imageColorSpace = space;
  sci.imageExtent = extent_;
  sci.imageArrayLayers = 1;
  sci.imageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                   (readable_ ? VK_IMAGE_USAGE_TRANSFER_SRC_BIT : 0);
  sci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  sci.preTransform = caps.currentTransform;
  sci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  sci.presentMode = VK_PRESENT_MODE_FIFO_KHR;  // always available; paces the loop to the display
  sci.clipped = VK_TRUE;
  check(vkCreateSwapchainKHR(device_, &sci, nullptr, &swapchain_), "vkCreateSwapchainKHR");
  std::uint32_t n = 0;
  vkGetSwapchainImagesKHR(device_, swapchain_, &n, nullptr);
  images_.resize(n);
  vkGetSwapchainImagesKHR(device_, swapchain_, &n, images_.data());

  if (!render_pass_) {
    // The frame is already in the image (copied by transfers); the panel is drawn over it.
    VkAttachmentDescription color{};
    color.format = format_;
    color.samples = VK_SAMPLE_COUNT_1_BIT;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    color.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &ref;
    VkSubpassDependency deps[2]{};
    deps[0] = {VK_SUBPASS_EXTERNAL,
               0,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               0};
    deps[1] = {0,
               VK_SUBPASS_EXTERNAL,
               VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
               VK_PIPELINE_STAGE_TRANSFER_BIT,
               VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT,
               VK_ACCESS_TRANSFER_READ_BIT,
               0};
    VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rp.attachmentCount = 1;
    rp.pAttachments = &color;
    rp.subpassCount = 1;
    rp.pSubpasses = &sub;
    rp.dependencyCount = 2;
    rp.pDependencies = deps;
    check(vkCreateRenderPass(device_, &rp, nullptr, &render_pass_), "vkCreateRenderPass");
  }
  for (VkImage image : images_) {
    VkImageViewCreateInfo iv{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    iv.image = image;
    iv.viewType = VK_IMAGE_VIEW_TYPE_2D;
    iv.format = format_;
    iv.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view;
    check(vkCreateImageView(device_, &iv, nullptr, &view), "vkCreateImageView");
    views_.push_back(view);
    VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = render_pass_;
    fb.attachmentCount = 1;
    fb.pAttachments = &view;
    fb.width = extent_.width;
    fb.height = extent_.height;
    fb.layers = 1;
    VkFramebuffer framebuffer;
    check(vkCreateFramebuffer(device_, &fb, nullptr, &framebuffer), "vkCreateFramebuffer");
    framebuffers_.push_back(framebuffer);
    // One "rendered" semaphore per image: presentation of an image may still wait on its
    // semaphore when the next frame is submitted.
    VkSemaphoreCreateInfo semaphore{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore s;
    check(vkCreateSemaphore(device_, &semaphore, nullptr, &s), "vkCreateSemaphore");
    rendered_.push_back(s);
  }
}

void VulkanWindow::destroy_swapchain() {
  for (VkFramebuffer f : framebuffers_) vkDestroyFramebuffer(device_, f, nullptr);
  for (VkImageView v : views_) vkDestroyImageView(device_, v, nullptr);
  for (VkSemaphore s : rendered_) vkDestroySemaphore(device_, s, nullptr);
  framebuffers_.clear();
  views_.clear();
  rendered_.clear();
  images_.clear();
  if (swapchain_) vkDestroySwapchainKHR(device_, swapchain_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
}

void VulkanWindow::recreate_swapchain() {
  int w = 0, h = 0;
  glfwGetFramebufferSize(window_, &w, &h);
  while ((w == 0 || h == 0) && !glfwWindowShouldClose(window_)) {  // minimised: wait for a size
    glfwWaitEvents();
    glfwGetFramebufferSize(window_, &w, &h);
  }
  vkDeviceWaitIdle(device_);
  destroy_swapchain();  // the render pass stays: the panel's pipeline was made for it
  create_swapchain();
}

bool VulkanWindow::draw_frame(const std::function<void(VkCommandBuffer, VkImage)>& fill,
                              const std::function<void(VkCommandBuffer)>& overlay,
                              Screenshot* screenshot) {
  check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  if (stale_swapchain_) {
    recreate_swapchain();
    stale_swapchain_ = false;
  }
  std::uint32_t index = 0;
  const VkResult acquired =
      vkAcquireNextImageKHR(device_, swapchain_, UINT64_MAX, acquired_, VK_NULL_HANDLE, &index);
  if (acquired == VK_ERROR_OUT_OF_DATE_KHR) {
    recreate_swapchain();
    return false;
  }
  if (acquired != VK_SUBOPTIMAL_KHR) check(acquired, "vkAcquireNextImageKHR");
  // The fence is reset just before the submission that signals it: a frame whose recording
  // throws (an application's error in `fill`, say) must not leave the next frame waiting on a
  // fence nothing will signal. Such a frame still consumes the acquire semaphore, with an empty
  // submission that waits on it and signals the fence, so the next acquire finds it unsignalled.
  struct Unrecorded {
    VulkanWindow& w;
    bool done = false;
    ~Unrecorded() {
      if (done) return;
      const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT;
      VkSubmitInfo empty{VK_STRUCTURE_TYPE_SUBMIT_INFO};
      empty.waitSemaphoreCount = 1;
      empty.pWaitSemaphores = &w.acquired_;
      empty.pWaitDstStageMask = &stage;
      if (vkResetFences(w.device_, 1, &w.fence_) == VK_SUCCESS)
        (void)vkQueueSubmit(w.queue_, 1, &empty, w.fence_);
      w.stale_swapchain_ = true;
    }
  } unrecorded{*this};
  check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd_, &begin), "vkBeginCommandBuffer");
  const VkImage image = images_[index];
  image_barrier(cmd_, image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                VK_PIPELINE_STAGE_TRANSFER_BIT, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_TRANSFER_WRITE_BIT);
  fill(cmd_, image);
  image_barrier(cmd_, image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT,
                VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = render_pass_;
  rp.framebuffer = framebuffers_[index];
  rp.renderArea = {{0, 0}, extent_};
  vkCmdBeginRenderPass(cmd_, &rp, VK_SUBPASS_CONTENTS_INLINE);
  overlay(cmd_);
  vkCmdEndRenderPass(cmd_);
  const bool read = screenshot && readable_;
  const VkDeviceSize bytes = VkDeviceSize{extent_.width} * extent_.height * 4;
  if (read) {
    if (readback_.size < bytes) {
      destroy_host_buffer(readback_);
      readback_ = make_host_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    }
    image_barrier(cmd_, image, VK_IMAGE_LAYOUT_PRESENT_SRC_KHR,
                  VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                  VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {extent_.width, extent_.height, 1};
    vkCmdCopyImageToBuffer(cmd_, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback_.buffer, 1,
                           &copy);
    image_barrier(cmd_, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                  VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                  VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0);
    VkBufferMemoryBarrier host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
    host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    host.srcQueueFamilyIndex = host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    host.buffer = readback_.buffer;
    host.size = VK_WHOLE_SIZE;
    vkCmdPipelineBarrier(cmd_, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                         nullptr, 1, &host, 0, nullptr);
  }
  check(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");

  const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.waitSemaphoreCount = 1;
  submit.pWaitSemaphores = &acquired_;
  submit.pWaitDstStageMask = &wait_stage;
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd_;
  submit.signalSemaphoreCount = 1;
  submit.pSignalSemaphores = &rendered_[index];
  check(vkResetFences(device_, 1, &fence_), "vkResetFences");
  check(vkQueueSubmit(queue_, 1, &submit, fence_), "vkQueueSubmit");
  unrecorded.done = true;  // the frame's own submission owns the semaphore and fence
  VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  present.waitSemaphoreCount = 1;
  present.pWaitSemaphores = &rendered_[index];
  present.swapchainCount = 1;
  present.pSwapchains = &swapchain_;
  present.pImageIndices = &index;
  const VkResult presented = vkQueuePresentKHR(queue_, &present);

  if (screenshot) {
    check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    screenshot->width = read ? static_cast<int>(extent_.width) : 0;
    screenshot->height = read ? static_cast<int>(extent_.height) : 0;
    screenshot->rgb.clear();
    if (read) {
      const auto* px = static_cast<const std::uint8_t*>(readback_.mapped);
      const std::size_t n = std::size_t{extent_.width} * extent_.height;
      screenshot->rgb.resize(3 * n);
      const bool swap = bgra();
      for (std::size_t i = 0; i < n; ++i) {
        screenshot->rgb[3 * i] = px[4 * i + (swap ? 2 : 0)];
        screenshot->rgb[3 * i + 1] = px[4 * i + 1];
        screenshot->rgb[3 * i + 2] = px[4 * i + (swap ? 0 : 2)];
      }
    }
  }
  if (presented == VK_ERROR_OUT_OF_DATE_KHR || presented == VK_SUBOPTIMAL_KHR ||
      acquired == VK_SUBOPTIMAL_KHR) {
    recreate_swapchain();
  } else {
    check(presented, "vkQueuePresentKHR");
  }
  return true;
}

void VulkanWindow::run_once(const std::function<void(VkCommandBuffer)>& record) {
  check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
  check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd_, &begin), "vkBeginCommandBuffer");
  record(cmd_);
  check(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd_;
  check(vkResetFences(device_, 1, &fence_),
        "vkResetFences");  // as draw_frame: never left unsignalled
  check(vkQueueSubmit(queue_, 1, &submit, fence_), "vkQueueSubmit");
  check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
}

VkBuffer VulkanWindow::staging(VkDeviceSize bytes, void** mapped) {
  if (staging_.size < bytes) {
    check(vkWaitForFences(device_, 1, &fence_, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    destroy_host_buffer(staging_);
    staging_ = make_host_buffer(bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  }
  *mapped = staging_.mapped;
  return staging_.buffer;
}

void VulkanWindow::wait_idle() const {
  vkDeviceWaitIdle(device_);
}

std::uint32_t VulkanWindow::memory_type(std::uint32_t bits, VkMemoryPropertyFlags wanted) const {
  VkPhysicalDeviceMemoryProperties props;
  vkGetPhysicalDeviceMemoryProperties(physical_, &props);
  for (std::uint32_t i = 0; i < props.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  throw WindowError("no host-visible memory for staging");
}

VulkanWindow::HostBuffer VulkanWindow::make_host_buffer(VkDeviceSize bytes,
                                                        VkBufferUsageFlags usage) {
  HostBuffer b;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = bytes;
  info.usage = usage;
  check(vkCreateBuffer(device_, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                              VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  check(vkAllocateMemory(device_, &alloc, nullptr, &b.memory), "vkAllocateMemory");
  check(vkBindBufferMemory(device_, b.buffer, b.memory, 0), "vkBindBufferMemory");
  check(vkMapMemory(device_, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  b.size = bytes;
  return b;
}

void VulkanWindow::destroy_host_buffer(HostBuffer& b) {
  if (b.buffer) vkDestroyBuffer(device_, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(device_, b.memory, nullptr);
  b = HostBuffer{};
}

}  // namespace voxfield::demo
