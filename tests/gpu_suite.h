// Helpers of the Vulkan backend's suites (test_gpu.cpp, test_gpu_render.cpp): the shared validated
// context, whether GPU tests are wanted, and seeded random worlds.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "backends.h"
#include "gpu/vulkan_context.h"
#include "voxfield/vectors.h"
#include "voxfield/world.h"

namespace voxfield::test {

inline std::shared_ptr<gpu::Context> validated_context() {
  return testing_backends::vulkan_context();
}

// A context of its own, validated, whose storage-buffer range is lowered to `range_bytes`
// (ContextOptions::max_storage_buffer_bytes, as a user sharing a device would): the paths that cut
// work into slabs or bind buffers in windows run on small inputs.
inline std::shared_ptr<gpu::Context> capped_context(std::uint64_t range_bytes) {
  gpu::ContextOptions co;
  co.validation = true;
  co.max_storage_buffer_bytes = range_bytes;
  return gpu::Context::create(co);
}

// A capped context beside the shared one (its messages cleared), for tests that hold what the
// capped device computes in parts or windows to what a device binding everything whole computes.
struct CappedAndWhole {
  std::shared_ptr<gpu::Context> small, whole;
};
inline CappedAndWhole capped_and_whole(std::uint64_t range_bytes) {
  CappedAndWhole c{capped_context(range_bytes), validated_context()};
  c.whole->clear_validation_messages();
  return c;
}

// The validation layer (synchronisation validation included) said nothing since the context's
// messages were last cleared.
inline void expect_no_validation_messages(gpu::Context& ctx) {
  const auto messages = ctx.validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
}

// The text of the installed shader include voxfield_vectors.glsl, for test kernels to prepend.
inline std::string vectors_glsl_include() {
  std::ifstream in(std::string(VOXFIELD_INCLUDE_DIR) + "/voxfield/glsl/voxfield_vectors.glsl");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// World points of a vector volume for the sampling tests, from volume coordinates in
// [-0.2, 1.2]^3 and none within 1e-3 of a face (where float and double may disagree on inside):
// `points` as the GPU reads them (x, y, z, 0 floats), `world` the same points as doubles.
struct VolumePoints {
  std::vector<float> points;
  std::vector<Vec3d> world;
};
inline VolumePoints volume_points(const VectorVolume& v, std::uint32_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0, 1);
  VolumePoints out{std::vector<float>(4 * static_cast<std::size_t>(n)), std::vector<Vec3d>(n)};
  for (std::uint32_t i = 0; i < n; ++i) {
    Vec3d u;
    for (int a = 0; a < 3; ++a) {
      do u[a] = -0.2 + 1.4 * u01(rng);
      while (std::abs(u[a]) < 1e-3 || std::abs(u[a] - 1) < 1e-3);
    }
    const Vec3d w = v.to_world(u);
    for (int a = 0; a < 3; ++a) out.points[4 * i + a] = static_cast<float>(w[a]);
    out.world[i] = {out.points[4 * i], out.points[4 * i + 1], out.points[4 * i + 2]};
  }
  return out;
}

// A texture of random unit directions and strengths in [0, 1).
inline VectorTexture random_vector_texture(Vec3i resolution, VectorStorage storage,
                                           std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1, 1), u01(0, 1);
  VectorTexture tex(resolution, storage);
  for (std::int64_t i = 0; i < tex.voxel_count(); ++i) {
    Vec3d d{unit(rng), unit(rng), unit(rng)};
    d = d.length() > 0 ? d.normalized() : Vec3d{1, 0, 0};
    tex.set(i, {static_cast<float>(d.x), static_cast<float>(d.y), static_cast<float>(d.z),
                static_cast<float>(u01(rng))});
  }
  return tex;
}

// Records `record(cmd)` into a command buffer of the context's pool as an application would, then
// submits it and waits for it.
template <class F>
void run_commands(gpu::Context::Impl& c, F&& record) {
  VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  ai.commandPool = c.command_pool;
  ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  ai.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  ASSERT_EQ(vkAllocateCommandBuffers(c.device, &ai, &cmd), VK_SUCCESS);
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  vkBeginCommandBuffer(cmd, &bi);
  record(cmd);
  vkEndCommandBuffer(cmd);
  c.submit_and_wait(cmd);
  vkFreeCommandBuffers(c.device, c.command_pool, 1, &cmd);
}

inline bool gpu_tests_wanted() {
  if (!gpu::built_with_vulkan()) return false;
  return std::getenv("VOXFIELD_SKIP_GPU_TESTS") == nullptr;
}

inline World random_world(Vec3i size, int chunk_edge, double density, std::uint32_t seed) {
  World w(chunk_edge, Box3i::from_size(size));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (int z = 0; z < size.z; ++z)
    for (int y = 0; y < size.y; ++y)
      for (int x = 0; x < size.x; ++x)
        if (u(rng) < density)
          w.voxels.set({x, y, z}, static_cast<std::uint8_t>(1 + (x + y + z) % 200));
  // A solid block so that some chunks are uniform and some signed distances are long.
  w.voxels.fill(Box3i{{0, 0, 0}, {std::min(size.x, 16), std::min(size.y, 16), std::min(size.z, 9)}},
                7);
  return w;
}

}  // namespace voxfield::test
