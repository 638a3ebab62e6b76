// One test body per behaviour, run on each backend (the CPU, and Vulkan where this build has it):
// the parameter of the TEST_P suites that check distance fields, the algorithm family and the
// incremental field on both. The Vulkan instances run on one shared context with the Khronos
// validation layer (synchronisation validation included), and fail on any message from it.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "voxfield/distance_executor.h"
#include "voxfield/gpu.h"

namespace voxfield::testing_backends {

inline std::shared_ptr<gpu::Context> vulkan_context() {
  static std::shared_ptr<gpu::Context> ctx = [] {
    gpu::ContextOptions o;
    o.validation = true;
    return gpu::Context::create(o);
  }();
  return ctx;
}

// Skips a Vulkan instance on a build without the backend or when VOXFIELD_SKIP_GPU_TESTS is set.
#define VOXFIELD_SKIP_UNLESS_BACKEND(b)                                                  \
  if ((b) == ::voxfield::Backend::kVulkan &&                                             \
      (!::voxfield::gpu::built_with_vulkan() || std::getenv("VOXFIELD_SKIP_GPU_TESTS"))) \
  GTEST_SKIP() << "no Vulkan backend in this build (or VOXFIELD_SKIP_GPU_TESTS)"

inline std::string backend_test_name(const ::testing::TestParamInfo<Backend>& info) {
  return backend_name(info.param);
}

// True under AddressSanitizer or ThreadSanitizer, where the Vulkan instances of the long suites run
// a sample of their cases: what the sanitizers check there is voxfield's host code, which every
// case runs alike, while lavapipe's shader emulation under instrumentation costs minutes. The
// optimised build runs every case.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitizedBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif
#else
inline constexpr bool kSanitizedBuild = false;
#endif

// The executor of `backend`: the CPU, or the shared Vulkan context.
inline Executor executor_of(Backend backend) {
  return backend == Backend::kVulkan ? Executor(vulkan_context()) : Executor();
}

// The exact field on `backend`, through the distance module's one API.
inline DistanceField exact_field(Backend backend, const World& world,
                                 const DistanceOptions& options) {
  return compute_distance_field(executor_of(backend), world, options);
}

// Fails the current test if the validation layer reported anything since the last call.
inline void expect_no_validation_messages(Backend backend) {
  if (backend != Backend::kVulkan) return;
  const auto messages = vulkan_context()->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
  vulkan_context()->clear_validation_messages();
}

}  // namespace voxfield::testing_backends
