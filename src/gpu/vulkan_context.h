// voxfield GPU compute layer — the Vulkan objects behind gpu::Context (internal): the device,
// buffers and submission. Kernels are in kernel.h, recording and barriers in recorder.h.
//
// Vulkan functions come through volk, which opens the loader at run time: a machine without
// libvulkan still starts, and gets GpuUnavailable instead of a failed dynamic link.
#pragma once

#include <volk.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <span>
#include <string>
#include <vector>

#include "gpu/kernel.h"
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

  // What the recorder knows of the commands recorded so far on this buffer (recorder.h): the
  // last write, the stages and accesses that have been made to see it, the reads since it.
  struct Sync {
    VkPipelineStageFlags write_stages = 0;
    VkAccessFlags write_access = 0;
    VkPipelineStageFlags visible_stages = 0;
    VkAccessFlags visible_access = 0;
    VkPipelineStageFlags read_stages = 0;
  };
  Sync sync;

 private:
  void release();
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

class DescriptorArena;

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
  bool float64 = false;  // shaderFloat64 is enabled on the device
  bool lost = false;     // the device was lost (GpuDeviceLost): nothing more is submitted

  DeviceInfo info;
  Counters counters;
  mutable std::mutex messages_mutex;
  std::vector<std::string> messages;

  // Every kernel made on this device, by the hash of its SPIR-V (kernel.h).
  KernelCache kernels;
  const Kernel& kernel(const ShaderSource& shader) { return kernels.get(device, shader); }
  static constexpr int kQueries = 64;  // timestamps per submission
  // Descriptor sets of the recorders that bring no arena of their own: one arena per context,
  // recycled when the last such recorder is done (recorder.cpp) rather than a pool created and
  // destroyed with every submission.
  std::unique_ptr<DescriptorArena> transient_sets;
  int transient_set_users = 0;

  // Reusable host-visible buffers for uploads and read-backs (grown when too small).
  Buffer upload, readback;
  Buffer& upload_buffer(VkDeviceSize bytes);
  Buffer& readback_buffer(VkDeviceSize bytes);

  std::uint32_t memory_type(std::uint32_t type_bits, VkMemoryPropertyFlags wanted) const;
  // Submits one command buffer and waits for it (one submit, one fence wait). Throws
  // GpuDeviceLost (and marks the context lost) when the device is lost.
  void submit_and_wait(VkCommandBuffer cmd);
  // Throws GpuDeviceLost when the device was lost earlier.
  void require_device() const;
  void finish_setup();
  // Lowers limits.maxStorageBufferRange to `bytes` (0: leaves it), as the options ask.
  void cap_storage_buffer_range(std::uint64_t bytes);
  void destroy();
};

}  // namespace voxfield::gpu
