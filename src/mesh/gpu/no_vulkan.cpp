// voxfield — the mesh module's GPU entry points in a build without the Vulkan backend: each
// reports GpuUnavailable (the CPU meshers, mesh.h, are always there).
#include "gpu/unavailable.h"
#include "voxfield/gpu_mesh.h"
#include "voxfield/gpu_terrain.h"

namespace voxfield::gpu {

Mesh marching_cubes(Context&, const ScalarVolume&, const MeshOptions&, const GpuMeshOptions&,
                    GpuMeshStats*) {
  built_without_vulkan();
}

Mesh marching_cubes(Context&, const TerrainField&, const GpuMeshOptions&, GpuMeshStats*) {
  built_without_vulkan();
}

struct TerrainRenderer::Impl {};

TerrainRenderer::TerrainRenderer(std::shared_ptr<Context>, Pyramid) {
  built_without_vulkan();
}
TerrainRenderer::~TerrainRenderer() = default;
std::uint64_t TerrainRenderer::sync(const TerrainField&) {
  built_without_vulkan();
}
std::uint64_t TerrainRenderer::sync(const TerrainField&, const Box3i&) {
  built_without_vulkan();
}
std::uint64_t TerrainRenderer::sync(const TerrainField&, std::span<const Box3i>) {
  built_without_vulkan();
}
Image TerrainRenderer::render(const TerrainView&, TerrainDrawStats*) {
  built_without_vulkan();
}
std::uint64_t TerrainRenderer::last_triangles() const {
  return 0;
}
Context& TerrainRenderer::context() {
  built_without_vulkan();
}

}  // namespace voxfield::gpu
