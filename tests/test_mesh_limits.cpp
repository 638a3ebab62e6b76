// voxfield — the meshers against the memory limit (voxfield/limits.h): a mesh's arrays are
// counted before they are allocated, on both paths (the whole-volume passes, and the chunked
// driver through an analytic gradient), and refused by name past the limit.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/mesh.h"

using namespace voxfield;

namespace {

struct LimitGuard {
  ~LimitGuard() { set_default_memory_limit(0); }
};

}  // namespace

// The arrays are 24 bytes a vertex and 4 an index: at exactly their bytes every mesher meshes, one
// byte less and it is refused with the vertex count in the message. (Each refusal compares one
// request with the limit; everything else these passes ask for is a few hundred kB.)
TEST(MeshLimits, AMeshsArraysAreCountedExactlyBeforeTheyAreAllocated) {
  // Signs alternating like a 3-D checkerboard: every lattice edge crosses, every cell is active.
  const Vec3i n{48, 48, 48};
  std::vector<float> values(static_cast<std::size_t>(n.x) * n.y * n.z);
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x)
        values[static_cast<std::size_t>(x + n.x * (y + n.y * z))] = (x + y + z) % 2 ? 1.f : -1.f;
  const ScalarVolume vol{n, values.data()};
  const LimitGuard guard;
  for (const Mesher m : {Mesher::kMarchingCubes, Mesher::kSurfaceNets, Mesher::kDualContouring})
    for (const bool chunked : {false, true}) {
      MeshOptions o;
      o.algorithm = m;
      if (chunked)
        o.gradient = [](const std::array<double, 3>&) { return std::array<double, 3>{0, 0, 1}; };
      const std::string name = std::string(mesher_name(m)) + (chunked ? " chunked" : "");
      set_default_memory_limit(0);
      const Mesh mesh = mesh_volume(vol, o);
      const std::uint64_t bytes = mesh.vertex_count() * 24 + mesh.indices.size() * 4;
      ASSERT_GT(mesh.vertex_count(), 40u * 40 * 40) << name;
      set_default_memory_limit(bytes);
      EXPECT_EQ(mesh_volume(vol, o).vertex_count(), mesh.vertex_count()) << name;
      set_default_memory_limit(bytes - 1);
      try {
        (void)mesh_volume(vol, o);
        ADD_FAILURE() << name << " was not refused";
      } catch (const ResourceLimitError& e) {
        EXPECT_NE(std::string(e.what()).find("a mesh of " + std::to_string(mesh.vertex_count()) +
                                             " vertices"),
                  std::string::npos)
            << e.what();
      }
    }
}
