// voxfield — the mesh module's entry shared by mesh_volume() and mesh_world() (internal).
#pragma once

#include <cstdint>
#include <vector>

#include "chunked_mesh.h"
#include "voxfield/mesh.h"

namespace voxfield::detail::mesh {

// mesh_volume(), also giving each vertex's source sample (the inside sample it was made from,
// as an index x fastest) when `sources` is not null.
// `voxel_faces`: the volume is a voxel world's signed field (see Lattice::voxel_faces).
Mesh mesh_lattice(const ScalarVolume& volume, const MeshOptions& options,
                  std::vector<std::uint64_t>* sources, bool voxel_faces = false);

// The lattice of a request, after checking it (InvalidArgument for a bad volume or options).
Lattice checked_lattice(const ScalarVolume& volume, const MeshOptions& options, bool voxel_faces);

// Meshes the chunks numbered `chunks` (ChunkGrid::coord order) into parts[i], in parallel, with
// progress and cancellation through options.interrupter.
void mesh_chunks(const Lattice& lattice, const ChunkGrid& grid, const MeshOptions& options,
                 const std::vector<std::int64_t>& chunks, std::vector<ChunkPart>& parts);

}  // namespace voxfield::detail::mesh
