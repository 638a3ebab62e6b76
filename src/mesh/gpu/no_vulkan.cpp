// voxfield — the mesh module's GPU entry points in a build without the Vulkan backend: each
// reports GpuUnavailable (the CPU meshers, mesh.h, are always there).
#include "gpu/unavailable.h"
#include "voxfield/gpu_mesh.h"

namespace voxfield::gpu {

Mesh marching_cubes(Context&, const ScalarVolume&, const MeshOptions&, const GpuMeshOptions&,
                    GpuMeshStats*) {
  built_without_vulkan();
}

Mesh marching_cubes(Context&, const TerrainField&, const GpuMeshOptions&, GpuMeshStats*) {
  built_without_vulkan();
}

}  // namespace voxfield::gpu
