// The GPU error tiers: which failure a Vulkan result becomes, and what a lost device leaves — every
// later call refuses at once with GpuDeviceLost instead of touching the dead device.
#include <gtest/gtest.h>

#include <cstdlib>

#include "gpu/vulkan_context.h"  // internal: the result-to-error mapping and the context's state
#include "voxfield/gpu_distance.h"
#include "voxfield/gpu_vulkan.h"

using namespace voxfield;

namespace {

template <class Expected>
void expect_exactly(VkResult result) {
  try {
    gpu::check(result, "vkTest");
    FAIL() << "no exception for VkResult " << result;
  } catch (const GpuUnavailable& e) {
    EXPECT_EQ(typeid(e), typeid(Expected)) << "VkResult " << result << ": " << e.what();
    EXPECT_NE(std::string(e.what()).find("vkTest"), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(GpuErrors, VulkanResultsMapToTheirTier) {
  EXPECT_NO_THROW(gpu::check(VK_SUCCESS, "vkTest"));
  expect_exactly<GpuDeviceLost>(VK_ERROR_DEVICE_LOST);
  expect_exactly<GpuOutOfMemory>(VK_ERROR_OUT_OF_DEVICE_MEMORY);
  expect_exactly<GpuOutOfMemory>(VK_ERROR_OUT_OF_HOST_MEMORY);
  expect_exactly<GpuOutOfMemory>(VK_ERROR_OUT_OF_POOL_MEMORY);
  expect_exactly<GpuUnavailable>(VK_ERROR_INITIALIZATION_FAILED);
  expect_exactly<GpuUnavailable>(VK_ERROR_FEATURE_NOT_PRESENT);
}

TEST(GpuErrors, ALostDeviceRefusesEveryLaterCall) {
  if (!gpu::built_with_vulkan() || std::getenv("VOXFIELD_SKIP_GPU_TESTS"))
    GTEST_SKIP() << "no Vulkan backend";
  std::shared_ptr<gpu::Context> ctx;
  try {
    ctx = gpu::Context::create();
  } catch (const GpuUnavailable& e) {
    GTEST_SKIP() << e.what();
  }
  World world(16, Box3i::from_size({16, 16, 16}));
  world.voxels.set({3, 4, 5}, 9);
  DistanceOptions options;
  options.metric = Metric::kManhattan;
  gpu::DynamicField field(ctx, world, options);  // works while the device is there
  EXPECT_FALSE(ctx->lost());
  EXPECT_EQ(field.download().distance({3, 4, 7}), 2.0);

  ctx->impl().lost = true;  // what submit_and_wait records when the driver reports the loss
  EXPECT_TRUE(ctx->lost());
  EXPECT_THROW(gpu::compute_distance_field(*ctx, world, options), GpuDeviceLost);
  EXPECT_THROW(field.rebuild(), GpuDeviceLost);
  EXPECT_THROW(field.download(), GpuDeviceLost);
  EXPECT_EQ(world.solid_count(), 1);  // the CPU-side world is untouched
}

namespace {

// An application's own Vulkan objects: an instance without any extension (so without
// VK_EXT_debug_utils) and a device on the first physical device's first compute queue.
struct AppDevice {
  gpu::AdoptedDevice handles;
  ~AppDevice() {
    if (handles.device) vkDestroyDevice(handles.device, nullptr);
    if (handles.instance) vkDestroyInstance(handles.instance, nullptr);
  }
  bool create() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_1;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    if (vkCreateInstance(&ici, nullptr, &handles.instance) != VK_SUCCESS) return false;
    std::uint32_t count = 1;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    vkEnumeratePhysicalDevices(handles.instance, &count, &physical);
    if (!physical) return false;
    std::uint32_t nq = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &nq, nullptr);
    std::vector<VkQueueFamilyProperties> families(nq);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &nq, families.data());
    std::uint32_t family = 0;
    while (family < nq && !(families[family].queueFlags & VK_QUEUE_COMPUTE_BIT)) ++family;
    if (family == nq) return false;
    const float priority = 1;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    if (vkCreateDevice(physical, &dci, nullptr, &handles.device) != VK_SUCCESS) return false;
    vkGetDeviceQueue(handles.device, family, 0, &handles.queue);
    handles.physical = physical;
    handles.queue_family = family;
    return true;
  }
};

double manhattan_at(gpu::Context& ctx, const World& world, Vec3i p) {
  DistanceOptions options;
  options.metric = Metric::kManhattan;
  return gpu::compute_distance_field(ctx, world, options).distance(p);
}

}  // namespace

// A validated context (its instance has VK_EXT_debug_utils), then a context adopted on an
// application's instance without it: both compute, and each tears down with its own instance's
// entry points whatever the order (adopting once replaced the process-wide table, and the first
// context's teardown then called a null vkDestroyDebugUtilsMessengerEXT).
TEST(GpuErrors, ContextsOnDifferentInstancesComputeAndTearDownInAnyOrder) {
  if (!gpu::built_with_vulkan() || std::getenv("VOXFIELD_SKIP_GPU_TESTS"))
    GTEST_SKIP() << "no Vulkan backend";
  std::shared_ptr<gpu::Context> validated;
  try {
    gpu::ContextOptions o;
    o.validation = true;
    validated = gpu::Context::create(o);
  } catch (const GpuUnavailable& e) {
    GTEST_SKIP() << e.what();
  }
  World world(16, Box3i::from_size({16, 16, 16}));
  world.voxels.set({3, 4, 5}, 9);
  for (const bool adopted_first_out : {true, false}) {
    SCOPED_TRACE(adopted_first_out ? "adopted context destroyed first"
                                   : "validated context destroyed first");
    if (!validated) {
      gpu::ContextOptions o;
      o.validation = true;
      validated = gpu::Context::create(o);
    }
    AppDevice app;
    ASSERT_TRUE(app.create());
    auto adopted = gpu::adopt(app.handles);
    EXPECT_EQ(manhattan_at(*adopted, world, {3, 4, 8}), 3.0);
    EXPECT_EQ(manhattan_at(*validated, world, {3, 4, 8}), 3.0);
    if (adopted_first_out) {
      adopted.reset();
      EXPECT_EQ(manhattan_at(*validated, world, {5, 4, 5}),
                2.0);  // still works on its own instance
      EXPECT_TRUE(validated->validation_messages().empty())
          << validated->validation_messages().front();
      validated.reset();
    } else {
      EXPECT_TRUE(validated->validation_messages().empty())
          << validated->validation_messages().front();
      validated.reset();
      EXPECT_EQ(manhattan_at(*adopted, world, {5, 4, 5}), 2.0);
      adopted.reset();
    }
  }
}
