// voxfield GPU compute layer — instance, device, queue, buffers and submission.
#include "vulkan_context.h"

#include <algorithm>
#include <cstring>
#include <sstream>
#include <utility>

#include "gpu/recorder.h"
#include "voxfield/gpu_vulkan.h"

namespace voxfield::gpu {

namespace {

std::string result_name(VkResult r) {
  switch (r) {
    case VK_ERROR_OUT_OF_HOST_MEMORY:
      return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
      return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED:
      return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST:
      return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT:
      return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT:
      return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT:
      return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER:
      return "VK_ERROR_INCOMPATIBLE_DRIVER: no Vulkan driver found";
    default:
      return "VkResult " + std::to_string(r);
  }
}

}  // namespace

void check(VkResult result, const char* what) {
  if (result == VK_SUCCESS) return;
  const std::string message =
      std::string("Vulkan: ") + what + " failed (" + result_name(result) + ")";
  switch (result) {
    case VK_ERROR_DEVICE_LOST:
      throw GpuDeviceLost(message);
    case VK_ERROR_OUT_OF_DEVICE_MEMORY:
    case VK_ERROR_OUT_OF_HOST_MEMORY:
    case VK_ERROR_OUT_OF_POOL_MEMORY:
    case VK_ERROR_FRAGMENTED_POOL:
      throw GpuOutOfMemory(message);
    default:
      throw GpuUnavailable(message);
  }
}

bool built_with_vulkan() {
  return true;
}

// ---- buffers --------------------------------------------------------------------------------

Buffer::Buffer(Context::Impl& ctx, VkDeviceSize bytes, VkBufferUsageFlags usage, bool host_visible)
    : device_(ctx.device), size_(bytes) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = std::max<VkDeviceSize>(bytes, 4);
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(device_, &info, nullptr, &buffer_), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, buffer_, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex =
      ctx.memory_type(req.memoryTypeBits, host_visible ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT |
                                                             VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                                       : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const VkResult r = vkAllocateMemory(device_, &alloc, nullptr, &memory_);
  if (r != VK_SUCCESS) {
    vkDestroyBuffer(device_, buffer_, nullptr);
    buffer_ = VK_NULL_HANDLE;
    const std::string message = "Vulkan: cannot allocate " + std::to_string(req.size) +
                                " bytes of " + (host_visible ? "host-visible" : "device") +
                                " memory (" + result_name(r) + ")";
    if (r == VK_ERROR_DEVICE_LOST) throw GpuDeviceLost(message);
    throw GpuOutOfMemory(message);
  }
  check(vkBindBufferMemory(device_, buffer_, memory_, 0), "vkBindBufferMemory");
  if (host_visible)
    check(vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_), "vkMapMemory");
}

Buffer::~Buffer() {
  release();
}

Buffer::Buffer(Buffer&& o) noexcept {
  *this = std::move(o);
}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    release();
    device_ = std::exchange(o.device_, VK_NULL_HANDLE);
    buffer_ = std::exchange(o.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(o.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(o.size_, 0);
    mapped_ = std::exchange(o.mapped_, nullptr);
    sync = std::exchange(o.sync, Sync{});
  }
  return *this;
}

void Buffer::release() {
  if (device_ == VK_NULL_HANDLE) return;
  if (buffer_) vkDestroyBuffer(device_, buffer_, nullptr);
  if (memory_) vkFreeMemory(device_, memory_, nullptr);  // unmaps too
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

std::uint32_t Context::Impl::memory_type(std::uint32_t type_bits,
                                         VkMemoryPropertyFlags wanted) const {
  for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
    if ((type_bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted)
      return i;
  // Device-local was only a preference (integrated GPUs and lavapipe may not advertise it).
  if (!(wanted & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT))
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
      if (type_bits & (1u << i)) return i;
  throw GpuUnavailable("Vulkan: no suitable memory type");
}

Buffer& Context::Impl::upload_buffer(VkDeviceSize bytes) {
  if (upload.size() < bytes)
    upload = Buffer(*this, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, /*host_visible=*/true);
  return upload;
}

Buffer& Context::Impl::readback_buffer(VkDeviceSize bytes) {
  if (readback.size() < bytes)
    readback = Buffer(*this, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, /*host_visible=*/true);
  return readback;
}

// ---- submission -----------------------------------------------------------------------------

void Context::Impl::require_device() const {
  if (lost)
    throw GpuDeviceLost("Vulkan: the device " + info.name +
                        " was lost earlier; make a new context");
}

void Context::Impl::submit_and_wait(VkCommandBuffer cmd) {
  require_device();
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &cmd;
  try {
    check(vkResetFences(device, 1, &fence), "vkResetFences");
    check(vkQueueSubmit(queue, 1, &submit, fence), "vkQueueSubmit");
    ++counters.submits;
    check(vkWaitForFences(device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    ++counters.fence_waits;
  } catch (const GpuDeviceLost&) {
    lost = true;  // every later submission refuses at once instead of touching a dead device
    throw;
  }
}

// ---- instance and device --------------------------------------------------------------------

namespace {

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* impl = static_cast<Context::Impl*>(user);
  const char* level =
      severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning";
  std::lock_guard lock(impl->messages_mutex);
  impl->messages.push_back(std::string(level) + ": " +
                           (data && data->pMessage ? data->pMessage : "?"));
  return VK_FALSE;
}

bool has_layer(const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
    return std::strcmp(l.layerName, name) == 0;
  });
}

const char* type_name(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    default:
      return "other";
  }
}

int preference(VkPhysicalDeviceType t) {
  switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return 1;
    default:
      return 0;
  }
}

std::once_flag volk_once;
VkResult volk_status = VK_ERROR_INITIALIZATION_FAILED;
std::mutex volk_table_mutex;

// Loads the Vulkan loader (once per process) and fills volk's process-wide table of core entry
// points from the first instance voxfield sees, never again: those entry points are the loader's
// trampolines, which dispatch on the handle they are given and so serve every instance and device
// in the process. Reloading per context would race with other threads' calls and would replace
// the table an application (or an earlier context) relies on. Extension entry points are per
// instance and stay with their context (Impl::destroy_messenger).
void load_vulkan(VkInstance instance) {
  std::lock_guard lock(volk_table_mutex);
  if (volkGetLoadedInstance() == VK_NULL_HANDLE) volkLoadInstance(instance);
}

void require_loader() {
  std::call_once(volk_once, [] { volk_status = volkInitialize(); });
  if (volk_status != VK_SUCCESS)
    throw GpuUnavailable("Vulkan: no Vulkan loader (libvulkan.so.1) on this machine");
}

}  // namespace

std::string DeviceInfo::api_version_string() const {
  std::ostringstream os;
  os << VK_API_VERSION_MAJOR(api_version) << "." << VK_API_VERSION_MINOR(api_version) << "."
     << VK_API_VERSION_PATCH(api_version);
  return os.str();
}

void Context::Impl::destroy() {
  if (device) {
    vkDeviceWaitIdle(device);
    upload = Buffer();
    readback = Buffer();
    transient_sets.reset();
    kernels.destroy(device);
    if (timestamps) vkDestroyQueryPool(device, timestamps, nullptr);
    if (fence) vkDestroyFence(device, fence, nullptr);
    if (command_pool) vkDestroyCommandPool(device, command_pool, nullptr);
    if (owns_device) vkDestroyDevice(device, nullptr);
    device = VK_NULL_HANDLE;
  }
  if (instance && owns_device) {
    if (messenger && destroy_messenger) destroy_messenger(instance, messenger, nullptr);
    vkDestroyInstance(instance, nullptr);
  }
  instance = VK_NULL_HANDLE;
}

std::shared_ptr<Context> Context::create(const ContextOptions& options) {
  require_loader();

  auto impl = std::make_unique<Impl>();
  Impl& s = *impl;
  struct Guard {  // destroys what was created if anything below throws
    Impl* s;
    ~Guard() {
      if (s) s->destroy();
    }
  } guard{&s};

  constexpr const char* kValidation = "VK_LAYER_KHRONOS_validation";
  std::vector<const char*> layers, extensions;
  if (options.validation) {
    if (!has_layer(kValidation))
      throw GpuUnavailable(
          "Vulkan: validation requested but VK_LAYER_KHRONOS_validation is not installed "
          "(Debian package vulkan-validationlayers)");
    layers.push_back(kValidation);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "voxfield";
  app.pEngineName = "voxfield";
  app.apiVersion = VK_API_VERSION_1_1;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  VkDebugUtilsMessengerCreateInfoEXT mci{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mci.pfnUserCallback = on_validation_message;
  mci.pUserData = &s;
  if (options.validation) {
    features.pNext = &mci;  // also catches messages from instance creation itself
    ici.pNext = &features;
  }
  check(vkCreateInstance(&ici, nullptr, &s.instance), "vkCreateInstance");
  load_vulkan(s.instance);
  if (options.validation) {
    const auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(s.instance, "vkCreateDebugUtilsMessengerEXT"));
    s.destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(s.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (!create_messenger || !s.destroy_messenger)
      throw GpuUnavailable("Vulkan: the validation layer is on but VK_EXT_debug_utils is missing");
    check(create_messenger(s.instance, &mci, nullptr, &s.messenger),
          "vkCreateDebugUtilsMessengerEXT");
  }

  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(s.instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(s.instance, &count, devices.data());
  // The usable devices in the loader's order, each with its first compute queue family.
  struct Usable {
    VkPhysicalDevice device;
    std::uint32_t family;
    int preference;
  };
  std::vector<Usable> usable;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(d, &props);
    if (props.apiVersion < VK_API_VERSION_1_1) continue;
    if (!options.allow_software && props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU) continue;
    std::uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> families(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(d, &nq, families.data());
    for (std::uint32_t f = 0; f < nq; ++f) {
      if (!(families[f].queueFlags & VK_QUEUE_COMPUTE_BIT)) continue;
      usable.push_back({d, f, preference(props.deviceType)});
      break;
    }
  }
  if (usable.empty())
    throw GpuUnavailable(std::string("Vulkan: no device with a compute queue") +
                         (options.allow_software ? "" : " (software devices excluded)"));
  // The most capable kind present (discrete, integrated, virtual, software); without an index
  // its first device, with one the device of that index among them, modulo their number — so the
  // node-local ranks of a job spread over a node's GPUs and never fall back to a software device.
  int best = usable[0].preference;
  for (const Usable& u : usable) best = std::max(best, u.preference);
  std::vector<const Usable*> kind;
  for (const Usable& u : usable)
    if (u.preference == best) kind.push_back(&u);
  const Usable* chosen =
      kind[options.device_index >= 0 ? static_cast<std::size_t>(options.device_index) % kind.size()
                                     : 0];
  s.physical = chosen->device;
  s.queue_family = chosen->family;
  const float priority = 1;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = s.queue_family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  // Doubles in shaders where the device has them: the vector-field passes compute in double
  // precision to match the CPU bit for bit (gpu_vectors.h); nothing else needs a feature.
  VkPhysicalDeviceFeatures supported{}, enabled{};
  vkGetPhysicalDeviceFeatures(s.physical, &supported);
  enabled.shaderFloat64 = supported.shaderFloat64;
  s.float64 = supported.shaderFloat64 == VK_TRUE;
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.pEnabledFeatures = &enabled;
  check(vkCreateDevice(s.physical, &dci, nullptr, &s.device), "vkCreateDevice");
  vkGetDeviceQueue(s.device, s.queue_family, 0, &s.queue);
  s.finish_setup();
  s.cap_storage_buffer_range(options.max_storage_buffer_bytes);
  guard.s = nullptr;
  return std::make_shared<Context>(std::move(impl));
}

// What a created and an adopted device both need: properties, the command pool, the fence, the
// timestamp pool (kernels are made on first use). Device functions go through the loader's dispatch
// (volk's instance-level table, never volkLoadDevice), so contexts on different devices can
// coexist.
void Context::Impl::finish_setup() {
  Impl& s = *this;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(s.physical, &props);
  s.limits = props.limits;
  vkGetPhysicalDeviceMemoryProperties(s.physical, &s.memory);
  s.info.name = props.deviceName;
  s.info.type = type_name(props.deviceType);
  s.info.hardware = props.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
  s.info.api_version = props.apiVersion;
  std::uint32_t nq = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(s.physical, &nq, nullptr);
  std::vector<VkQueueFamilyProperties> families(nq);
  vkGetPhysicalDeviceQueueFamilyProperties(s.physical, &nq, families.data());
  if (s.queue_family >= nq || !(families[s.queue_family].queueFlags & VK_QUEUE_COMPUTE_BIT))
    throw GpuUnavailable("Vulkan: queue family " + std::to_string(s.queue_family) +
                         " has no compute queue");
  s.timestamp_period_ns =
      families[s.queue_family].timestampValidBits ? props.limits.timestampPeriod : 0;

  VkCommandPoolCreateInfo cp{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = s.queue_family;
  check(vkCreateCommandPool(s.device, &cp, nullptr, &s.command_pool), "vkCreateCommandPool");
  VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  check(vkCreateFence(s.device, &fi, nullptr, &s.fence), "vkCreateFence");
  if (s.timestamp_period_ns > 0) {
    VkQueryPoolCreateInfo qp{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qp.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qp.queryCount = kQueries;
    check(vkCreateQueryPool(s.device, &qp, nullptr, &s.timestamps), "vkCreateQueryPool");
  }
}

std::shared_ptr<Context> adopt(const AdoptedDevice& app) {
  if (!app.instance || !app.physical || !app.device || !app.queue)
    throw InvalidArgument("gpu::adopt: instance, physical device, device and queue are all needed");
  require_loader();
  load_vulkan(app.instance);
  auto impl = std::make_unique<Context::Impl>();
  Context::Impl& s = *impl;
  s.owns_device = false;
  s.float64 = app.shader_float64;
  s.instance = app.instance;
  s.physical = app.physical;
  s.device = app.device;
  s.queue = app.queue;
  s.queue_family = app.queue_family;
  struct Guard {
    Context::Impl* s;
    ~Guard() {
      if (s) s->destroy();
    }
  } guard{&s};
  s.finish_setup();
  s.cap_storage_buffer_range(app.max_storage_buffer_bytes);
  guard.s = nullptr;
  return std::make_shared<Context>(std::move(impl));
}

void Context::Impl::cap_storage_buffer_range(std::uint64_t bytes) {
  if (bytes == 0) return;
  // At least the largest buffer of a fixed size bound whole (a palette, 256 colours of 16 bytes),
  // and aligned as a binding's offset must be: windows of large buffers (split_buffer.h) start at
  // multiples of a power of two within the range.
  const std::uint64_t least =
      std::max<std::uint64_t>(limits.minStorageBufferOffsetAlignment, std::uint64_t{4096});
  if (bytes < least)
    throw InvalidArgument("GPU: a storage-buffer range of " + std::to_string(bytes) +
                          " bytes is below " + std::to_string(least) +
                          " (a palette's 4 KiB, and the device's storage-buffer offset alignment)");
  // Whole words: buffers are sized in 32-bit words, checked against the range before rounding.
  bytes &= ~std::uint64_t{3};
  if (bytes > 0 && bytes < limits.maxStorageBufferRange)
    limits.maxStorageBufferRange = static_cast<std::uint32_t>(bytes);
}

Context::Context(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Context::~Context() {
  if (impl_) impl_->destroy();
}
const DeviceInfo& Context::device() const {
  return impl_->info;
}
Counters Context::counters() const {
  return impl_->counters;
}
void Context::reset_counters() {
  impl_->counters = {};
}
bool Context::has_timestamps() const {
  return impl_->timestamps != VK_NULL_HANDLE;
}
bool Context::lost() const {
  return impl_->lost;
}

std::vector<std::string> Context::validation_messages() const {
  std::lock_guard lock(impl_->messages_mutex);
  return impl_->messages;
}

void Context::clear_validation_messages() {
  std::lock_guard lock(impl_->messages_mutex);
  impl_->messages.clear();
}

}  // namespace voxfield::gpu
