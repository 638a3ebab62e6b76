// voxfield — the mesh module's entry shared by mesh_volume() and mesh_world() (internal).
#pragma once

#include <cstdint>
#include <vector>

#include "voxfield/mesh.h"

namespace voxfield::detail::mesh {

// mesh_volume(), also giving each vertex's source sample (the inside sample it was made from,
// as an index x fastest) when `sources` is not null.
// `voxel_faces`: the volume is a voxel world's signed field (see Lattice::voxel_faces).
Mesh mesh_lattice(const ScalarVolume& volume, const MeshOptions& options, std::vector<std::uint64_t>* sources,
                  bool voxel_faces = false);

}  // namespace voxfield::detail::mesh
