// voxfield-demo — a GLFW window presenting through a Vulkan swapchain.
//
// Owns the instance, the device (one queue family that draws, computes and presents), the
// swapchain with a render pass for the panel drawn over the frame, and the per-frame command
// buffer and synchronisation. One frame is in flight at a time: voxfield's resident scene reuses
// its frame buffers, and on the software devices this demo is tested on a second frame in flight
// would only compete for the same CPU cores.
#pragma once

#include <volk.h>

#include <GLFW/glfw3.h>

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace voxfield::demo {

// Thrown when the window system or Vulkan cannot give the demo a window to present to.
class WindowError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// GLFW for the whole program: both kinds of window are opened inside one session, so falling back
// from Vulkan to OpenGL does not reconnect to the display.
struct GlfwSession {
  GlfwSession() {
    if (!glfwInit()) throw WindowError("GLFW cannot start (no display? run under xvfb-run)");
  }
  ~GlfwSession() { glfwTerminate(); }
  GlfwSession(const GlfwSession&) = delete;
  GlfwSession& operator=(const GlfwSession&) = delete;
};

class VulkanWindow {
 public:
  // Opens a width x height window titled `title` (inside a GlfwSession). Throws WindowError when
  // GLFW or Vulkan is not usable (no display, no loader, no device that can present to the window).
  VulkanWindow(int width, int height, const std::string& title, bool validation);
  ~VulkanWindow();
  VulkanWindow(const VulkanWindow&) = delete;
  VulkanWindow& operator=(const VulkanWindow&) = delete;

  GLFWwindow* window() const { return window_; }
  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physical() const { return physical_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queue_family() const { return family_; }
  VkRenderPass render_pass() const { return render_pass_; }
  std::uint32_t image_count() const { return static_cast<std::uint32_t>(images_.size()); }
  std::uint32_t min_image_count() const { return min_image_count_; }
  std::string device_name() const { return device_name_; }
  bool device_is_hardware() const { return hardware_; }
  bool float64() const { return float64_; }  // shaderFloat64 is enabled
  bool bgra() const { return format_ == VK_FORMAT_B8G8R8A8_UNORM; }
  int width() const { return static_cast<int>(extent_.width); }
  int height() const { return static_cast<int>(extent_.height); }

  // One frame. `fill` records the copy of the frame's pixels into `image` (in
  // TRANSFER_DST_OPTIMAL layout, width() x height()); `overlay` records draws inside the render
  // pass (the panel). With `screenshot`, the presented image is also read back into it as RGB
  // rows. Returns false when the swapchain had to be recreated (window resized): nothing was
  // drawn; ask the size again and retry.
  struct Screenshot {
    int width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
  };
  bool draw_frame(const std::function<void(VkCommandBuffer, VkImage)>& fill,
                  const std::function<void(VkCommandBuffer)>& overlay, Screenshot* screenshot);

  // A command buffer submitted and waited for at once (set-up work such as font uploads).
  void run_once(const std::function<void(VkCommandBuffer)>& record);
  // A host-visible buffer of at least `bytes` for staging CPU-rendered frames.
  VkBuffer staging(VkDeviceSize bytes, void** mapped);
  void wait_idle() const;

 private:
  void open(int width, int height, const std::string& title, bool validation);
  void release();
  void create_swapchain();
  void destroy_swapchain();
  void recreate_swapchain();
  std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags wanted) const;

  GLFWwindow* window_ = nullptr;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkSurfaceKHR surface_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t family_ = 0;
  std::string device_name_;
  bool hardware_ = false;
  bool float64_ = false;

  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent2D extent_{0, 0};
  bool readable_ = false;  // swapchain images allow TRANSFER_SRC (screenshots)
  std::uint32_t min_image_count_ = 2;
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  VkRenderPass render_pass_ = VK_NULL_HANDLE;

  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
  // A frame whose recording failed left its acquired image unpresented: the swapchain is made
  // again before the next acquire, so failed frames cannot use up its images.
  bool stale_swapchain_ = false;
  VkSemaphore acquired_ = VK_NULL_HANDLE;
  std::vector<VkSemaphore> rendered_;  // per swapchain image

  struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void* mapped = nullptr;
  };
  HostBuffer make_host_buffer(VkDeviceSize bytes, VkBufferUsageFlags usage);
  void destroy_host_buffer(HostBuffer& b);
  HostBuffer staging_, readback_;
};

}  // namespace voxfield::demo
