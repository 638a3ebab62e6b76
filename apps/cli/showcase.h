// voxfield showcase — what its sections share (the command is cmd_showcase.cpp; each larger
// section has its own showcase_*.cpp).
#pragma once

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/gpu.h"
#include "voxfield/render.h"
#include "voxfield/world.h"

namespace voxfield::cli {

struct Timing {
  std::string stage;
  double ms;
  std::string note;
};

// The Vulkan device for a section's GPU part (a software one too), or null after the report says
// why that part is not run here.
inline std::shared_ptr<gpu::Context> showcase_vulkan(std::ostream& md) {
  try {
    std::string why;
    return gpu::select_backend(Backend::kVulkan, {}, &why);
  } catch (const GpuUnavailable& e) {
    md << "\nOn Vulkan: not run here (" << e.what() << ").\n";
    return nullptr;
  }
}

// A picture's edge in pixels in a showcase of `size`³ worlds: `full` at the default size (256)
// and above, down to a quarter of it below 64. Every picture is drawn this size (the sections
// whose scenes do not follow --size too: the CSG models, the vector fields, the Stanford bunny,
// the terrain field), so that the small runs the tests make (--size 48, under the sanitizers too)
// stay short.
inline int picture_pixels(int full, int size) {
  return full * std::clamp(size, 64, 256) / 256;
}

inline std::string fixed(double v, int digits) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(digits) << v;
  return os.str();
}

// Meshes of the terrain: both meshers, their topology and cost, the peers on the same field (when
// `peers_script` exists and Debian's Python runs it), pictures, a .glb and a .ply. `sdf_npy` is
// the terrain's signed Euclidean field over its box, already written.
// Meshes in: a block of `terrain` meshed, written as `out`/terrain-block.obj, read back, voxelised
// and set against the block; its signed distance field; the Stanford bunny when
// scripts/fetch-test-meshes.sh has fetched it.
void showcase_mesh_input(const World& terrain, int size, const std::filesystem::path& out,
                         std::ostream& md, std::vector<Timing>& timings);
void showcase_meshing(const World& terrain, int world_size, const std::filesystem::path& out,
                      const std::filesystem::path& sdf_npy,
                      const std::filesystem::path& peers_script, const Camera& hero,
                      std::ostream& md, std::vector<Timing>& timings);

// A deformable terrain field: smooth hills in i8 / i16 / f32, shaped by brushes with incremental
// re-meshing (checked equal to fresh meshes), pictured before and after, exported as a .glb.
void showcase_terrain(const std::filesystem::path& out, std::uint64_t seed, int size,
                      std::ostream& md, std::vector<Timing>& timings);

// The terrain drawn on Vulkan with its skip and lighting fields computed there (the showcase's
// Manhattan 32 and Euclidean 16 over `box`), against `host_scene`'s frame of the same fields
// computed on the CPU: the picture, equality pixel for pixel, the bytes each way.
void showcase_device_scene(const std::filesystem::path& out, const World& world, const Box3i& box,
                           const RenderScene& host_scene, const Camera& camera,
                           const RenderOptions& options, std::ostream& md,
                           std::vector<Timing>& timings);

// Vector fields: agents flying through a volume, fixed steps, the visualiser, every algorithm
// against the definition, .fga and .vf exports; the flow around a terrain's solids under an edit.
void showcase_vectors(const std::filesystem::path& out, std::uint64_t seed, int size,
                      std::ostream& md, std::vector<Timing>& timings);

// The voxel compiler: the example CSG models (under `examples`/csg) compiled, pictured shaded and
// by variant, two voxelised into .vox files (pruned and whole-tree voxelisations checked equal).
void showcase_csg(const std::filesystem::path& examples, const std::filesystem::path& out, int size,
                  std::ostream& md, std::vector<Timing>& timings);

}  // namespace voxfield::cli
