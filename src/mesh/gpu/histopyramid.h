// voxfield — what the mesh module's GPU passes share (internal): the marching-cubes tables as the
// shaders read them, the HistoPyramid's levels and their recording, and the lattice checks of
// mesh_volume.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "gpu/recorder.h"
#include "shaders/layout.h"
#include "voxfield/box.h"
#include "voxfield/gpu_mesh.h"

namespace voxfield::gpu::mc {

// The passes' device buffers: bound as storage, filled and read back by copies.
constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// The CPU's case table (cube_cases.h), flattened as layout.h's VF_MC_* describe it.
std::vector<std::uint32_t> case_table();
// The pyramid's levels, base first: (offset, dims x, y, z); the top holds one element. `total`
// receives the elements of all levels.
std::vector<layout::ivec4> pyramid_levels(Vec3i cells, Pyramid kind, std::uint64_t& total);
// Records classify over every cell and one reduction per pyramid level above the base, as timed
// passes "classify" and "HistoPyramid". `buffers` are the passes' bindings (mesh_common.glsl, with
// the pyramid at 4 and the cell cases at 5); `p` is the frame's parameters (its pass.x is set per
// level and left at the top level's).
void record_pyramid(Recorder& rec, Context::Impl& c, Recorder::Buffers buffers,
                    layout::MeshParams& p, const std::vector<layout::ivec4>& levels);

// mesh_volume's checks of a lattice and its frame, and the GPU's 32-bit cell indices.
void check_lattice(Vec3i n, const std::array<double, 3>& origin,
                   const std::array<double, 3>& spacing);

}  // namespace voxfield::gpu::mc
