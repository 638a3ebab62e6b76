// Helpers of the Vulkan backend's suites (test_gpu.cpp, test_gpu_render.cpp): the shared validated
// context, whether GPU tests are wanted, and seeded random worlds.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>

#include "backends.h"
#include "voxfield/world.h"

namespace voxfield::test {

inline std::shared_ptr<gpu::Context> validated_context() {
  return testing_backends::vulkan_context();
}

// The text of the installed shader include voxfield_vectors.glsl, for test kernels to prepend.
inline std::string vectors_glsl_include() {
  std::ifstream in(std::string(VOXFIELD_INCLUDE_DIR) + "/voxfield/glsl/voxfield_vectors.glsl");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
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
