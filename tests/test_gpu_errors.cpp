// The GPU error tiers: which failure a Vulkan result becomes, and what a lost device leaves — every
// later call refuses at once with GpuDeviceLost instead of touching the dead device.
#include <gtest/gtest.h>

#include <cstdlib>

#include "gpu/vulkan_context.h"  // internal: the result-to-error mapping and the context's state
#include "voxfield/gpu_distance.h"

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
  if (!gpu::built_with_vulkan() || std::getenv("VOXFIELD_SKIP_GPU_TESTS")) GTEST_SKIP() << "no Vulkan backend";
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
