// voxfield — the mesh module's entry shared by mesh_volume() and mesh_world() (internal).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "chunked_mesh.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/terrain.h"

namespace voxfield::detail::mesh {

// mesh_volume(), also giving each vertex's source sample (the inside sample it was made from,
// as an index x fastest) when `sources` is not null.
// `voxel_faces`: the volume is a voxel world's signed field (see Lattice::voxel_faces).
Mesh mesh_lattice(const ScalarVolume& volume, const MeshOptions& options,
                  std::vector<std::uint64_t>* sources, bool voxel_faces = false);

// mesh_slab (mesh_slab.h) with the lattice's voxel_faces rule, also giving each part vertex's
// source sample (an index x fastest in the whole lattice) when `sources` is not null.
MeshSlab mesh_lattice_slab(const ScalarVolume& frame, int planes_z0, int plane_count,
                           const float* planes, const MeshOptions& options, int z_begin, int z_end,
                           bool voxel_faces, std::vector<std::uint64_t>* sources);

// The lattice of a request, after checking it (InvalidArgument for a bad volume or options).
// A volume without values is read through `fill` (Lattice::fill).
Lattice checked_lattice(const ScalarVolume& volume, const MeshOptions& options, bool voxel_faces,
                        const std::function<void(const Box3i&, float*)>* fill = nullptr);

// What a terrain field's lattice reads through (kept by the caller while the lattice is used).
struct TerrainSamples {
  std::function<void(const Box3i&, float*)> fill;
  std::function<std::array<std::uint8_t, 3>(std::uint64_t)> color;
};
// The terrain's frame (size, origin and spacing; no values) and the options it is meshed with
// (iso 0, inside per its sign convention).
ScalarVolume terrain_frame(const TerrainField& terrain);
MeshOptions terrain_options(const TerrainField& terrain, const MeshOptions& options);
// The lattice of a terrain field meshed with terrain_options(); `keep` holds its functions.
Lattice terrain_lattice(const TerrainField& terrain, const MeshOptions& terrain_options,
                        TerrainSamples& keep);

// What mesh_world() and WorldMeshChunks share (mesh_world.cpp). How many voxels of air the
// lattice reaches past the solid content for a world surface at `iso` (InvalidArgument for an
// iso mesh_world refuses); the signed field the surface is meshed from, clamped where the meshers
// stop reading; the lattice over `domain` (samples at voxel centres); the material that colours a
// vertex made from sample `p` (an air sample of an offset surface: its nearest voxel's); and an
// offset surface's exact normals from the field's nearest sites.
int world_surface_margin(double iso);
DistanceOptions world_field_options(double iso, Metric metric, const Box3i& domain);
ScalarVolume world_lattice_frame(const Box3i& domain);
std::uint8_t world_vertex_material(const World& world, const DistanceField& field, Vec3i p);
// Colours `mesh`'s vertices from the world's palette by their source samples (indices x fastest in
// the box `lattice`): world_vertex_material of each.
void color_by_sources(const World& world, const DistanceField& field, const Box3i& lattice,
                      const std::vector<std::uint64_t>& sources, Mesh& mesh);
std::function<std::array<double, 3>(const std::array<double, 3>&)> offset_gradient(
    const World& world, const DistanceField& field, Metric metric, bool outside);

// Meshes the chunks numbered `chunks` (ChunkGrid::coord order) into parts[i], in parallel, with
// progress and cancellation through options.interrupter.
void mesh_chunks(const Lattice& lattice, const ChunkGrid& grid, const MeshOptions& options,
                 const std::vector<std::int64_t>& chunks, std::vector<ChunkPart>& parts);
// Every chunk of the lattice (options.chunk_edge), in ChunkGrid order.
std::vector<ChunkPart> mesh_all_chunks(const Lattice& lattice, const MeshOptions& options);

}  // namespace voxfield::detail::mesh
