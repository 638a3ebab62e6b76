// voxfield GPU backend — the Vulkan objects behind gpu::Context (internal).
//
// Vulkan functions come through volk, which opens the loader at run time: a machine without
// libvulkan still starts, and gets GpuUnavailable instead of a failed dynamic link.
#pragma once

#include <volk.h>

#include <cstdint>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "voxfield/gpu.h"

namespace voxfield::gpu {

// Throws naming the call when a Vulkan call fails: GpuDeviceLost for a lost device, GpuOutOfMemory
// for exhausted device, host or pool memory, GpuUnavailable otherwise.
void check(VkResult result, const char* what);

// A buffer with its own memory (voxfield allocates a handful of large buffers, never one per
// chunk, so a general-purpose allocator is not needed).
class Buffer {
 public:
  Buffer() = default;
  Buffer(Context::Impl& ctx, VkDeviceSize bytes, VkBufferUsageFlags usage, bool host_visible);
  ~Buffer();
  Buffer(Buffer&& o) noexcept;
  Buffer& operator=(Buffer&& o) noexcept;

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  // Host pointer of a host-visible buffer (persistently mapped, coherent).
  void* mapped() const { return mapped_; }

 private:
  void release();
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

// Storage buffers 0..N-1 (and optionally push constants) for a family of compute pipelines, with
// a descriptor pool that holds one set at a time (reset for each submission that binds).
struct BindingLayout {
  VkDescriptorSetLayout set = VK_NULL_HANDLE;
  VkPipelineLayout pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  std::uint32_t bindings = 0;
};

// A compute pipeline made from embedded SPIR-V.
struct Pipeline {
  VkPipeline pipeline = VK_NULL_HANDLE;
  std::string name;
};

struct Context::Impl {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  // The messenger's destructor, fetched from this context's own instance: extension entry points
  // exist only on instances that enabled the extension, so volk's shared table cannot hold them.
  PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = nullptr;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  VkCommandPool command_pool = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkQueryPool timestamps = VK_NULL_HANDLE;
  double timestamp_period_ns = 0;  // 0: no timestamps on this queue
  VkPhysicalDeviceMemoryProperties memory{};
  VkPhysicalDeviceLimits limits{};
  bool owns_device = true;
  bool lost = false;  // the device was lost (GpuDeviceLost): nothing more is submitted

  DeviceInfo info;
  Counters counters;
  mutable std::mutex messages_mutex;
  std::vector<std::string> messages;

  // The distance pipelines (11 storage buffers, push constants) and the ray marcher (8 buffers).
  static constexpr std::uint32_t kBindings = 11;
  static constexpr std::uint32_t kPushBytes = 96;
  static constexpr std::uint32_t kRenderBindings = 8;
  BindingLayout field_layout, render_layout, jfa_layout, fim_layout;
  Pipeline edt_sites, edt_lines, edt_encode, render, jfa, jfa_seed, fim;

  // Reusable host-visible buffers for uploads and read-backs (grown when too small).
  Buffer upload, readback;
  Buffer& upload_buffer(VkDeviceSize bytes);
  Buffer& readback_buffer(VkDeviceSize bytes);

  std::uint32_t memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags wanted) const;
  void create_pipelines();
  Pipeline make_pipeline(const char* name, std::span<const std::uint32_t> spirv,
                         VkPipelineLayout layout);
  BindingLayout make_binding_layout(std::uint32_t bindings, std::uint32_t push_bytes);
  // A descriptor set binding `buffers` (one per binding, in order) from the layout's pool, which is
  // reset first: sets live until the next call for the same layout.
  VkDescriptorSet bind(const BindingLayout& layout, std::span<const Buffer* const> buffers);
  // A pool for one set of `buffers` storage buffers, for objects that keep their set across
  // submissions (the resident render scene); the caller destroys it.
  VkDescriptorPool make_descriptor_pool(std::uint32_t buffers);
  // Resets `pool` and allocates from it a set of `layout` binding `buffers` in order.
  VkDescriptorSet allocate_set(VkDescriptorPool pool, const BindingLayout& layout,
                               std::span<const Buffer* const> buffers);
  // Allocates a command buffer, lets `record` fill it, submits it and waits (freed after).
  template <class F>
  void run_commands(F&& record);
  // Submits one command buffer and waits for it (one submit, one fence wait). Throws
  // GpuDeviceLost (and marks the context lost) when the device is lost.
  void submit_and_wait(VkCommandBuffer cmd);
  // Throws GpuDeviceLost when the device was lost earlier.
  void require_device() const;
  void finish_setup();
  void destroy();
};

template <class F>
void Context::Impl::run_commands(F&& record) {
  require_device();
  VkCommandBufferAllocateInfo cba{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cba.commandPool = command_pool;
  cba.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cba.commandBufferCount = 1;
  VkCommandBuffer cmd;
  check(vkAllocateCommandBuffers(device, &cba, &cmd), "vkAllocateCommandBuffers");
  struct FreeCmd {
    Context::Impl& ctx;
    VkCommandBuffer cmd;
    ~FreeCmd() { vkFreeCommandBuffers(ctx.device, ctx.command_pool, 1, &cmd); }
  } free_cmd{*this, cmd};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");
  record(cmd);
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  submit_and_wait(cmd);
}

// Records a dispatch of `invocations` invocations of 64 (split over y when the x count would
// exceed the device limit) and counts it.
void dispatch(Context::Impl& ctx, VkCommandBuffer cmd, std::uint64_t invocations);
// A compute-to-compute (and transfer) memory barrier, counted.
void barrier(Context::Impl& ctx, VkCommandBuffer cmd, VkPipelineStageFlags src,
             VkAccessFlags src_access, VkPipelineStageFlags dst, VkAccessFlags dst_access);

}  // namespace voxfield::gpu
