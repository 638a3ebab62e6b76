// voxfield — meshes of a slab of sample planes, for programs that each hold only some planes of a
// lattice (the ranks of an MPI job: voxfield::mpi::mesh_volume and write_mesh_volume) and want the
// mesh one process makes of the whole lattice, array for array.
//
// mesh_volume meshes a whole lattice in Flying Edges' passes (src/mesh/flying_edges.cpp and
// flying_dual.cpp), numbering vertices and triangles by lattice row. Marching cubes: every row of
// samples (y, z) owns a run of vertex numbers — its crossings, then the centre vertices of the
// cell row it starts — and every cell row a run of triangles; a slab of sample planes [z_begin,
// z_end) owns one run of each, and its triangles use only its own vertices and those of the rows
// of plane z_end (the next slab's first rows). Surface nets and dual contouring: every cell row
// owns the vertices of its cells that quads reach and every sample row the quads of its crossed
// edges; a slab owns cell planes [z_begin, z_end) and the quads of sample planes [z_begin,
// z_end), which use its own vertices and those of cell plane z_begin - 1 (the slab before's last).
// Given the planes around it, a slab computes all of them with the whole lattice's samples and
// arithmetic: consecutive slabs' owned vertices and triangles, laid end to end (each slab's own
// vertices numbered after those of the slabs before, MeshSlab::number), are mesh_volume's mesh bit
// for bit, whatever the cuts.
#pragma once

#include <cstdint>
#include <utility>

#include "voxfield/mesh.h"

namespace voxfield {

// Whether mesh_slab meshes with these options: any mesher without an analytic value or gradient
// (what mesh_volume meshes in the whole-volume passes). The chunked pieces (mesh_pieces.h) serve
// the rest.
bool mesh_slab_applies(const MeshOptions& options);

// The sample planes [first, second) meshing the slab [z_begin, z_end) reads, within the lattice's
// `samples_z` planes. Marching cubes: one before (the gradients' stencils) to three past (plane
// z_end's rows, whose vertices the slab's triangles use, with their own stencils). The dual
// meshers: three before (the cell plane before, whose vertices its quads use, with dual
// contouring's one-sided differences two samples out) to three past (the quads that reach its
// last cells, and the stencils).
std::pair<int, int> mesh_slab_planes(int samples_z, int z_begin, int z_end,
                                     Mesher mesher = Mesher::kMarchingCubes);

struct MeshSlab {
  // The slab's own vertices, in mesh_volume's order, then the vertices its triangles use that
  // another slab owns (computed here the same way, bit for bit): marching cubes, those of plane
  // z_end's rows (the next slab's first; none when z_end is the lattice's last plane + 1); the dual
  // meshers, those of cell plane z_begin - 1 (the slab before's last; none when z_begin is 0). The
  // triangles of the slab's cells (marching cubes) or quads (the dual meshers), numbered within
  // `part`. No colours.
  Mesh part;
  std::uint64_t owned_vertices = 0;
  // Of the owned vertices, those the slab before's triangles use: the first plane's rows (marching
  // cubes; 0 for the dual meshers).
  std::uint64_t first_plane_vertices = 0;
  // Of the owned vertices, those the next slab's triangles use: the last cell plane's (the dual
  // meshers; 0 for marching cubes).
  std::uint64_t last_plane_vertices = 0;
  // The part's vertices past the owned ones are the slab before's (the dual meshers), not the next
  // slab's (marching cubes).
  bool lent_from_before = false;
  // The number in the whole mesh of the part's vertex i, the slab's own vertices being numbered
  // from first_vertex.
  std::uint64_t number(std::uint64_t i, std::uint64_t first_vertex) const {
    if (i < owned_vertices || !lent_from_before) return first_vertex + i;
    return first_vertex - (part.vertex_count() - owned_vertices) + (i - owned_vertices);
  }
};

// Meshes the slab [z_begin, z_end) of the lattice `frame` describes (its size, origin and
// spacing; frame.values is not read) from `planes`: the samples of planes [planes_z0, planes_z0 +
// plane_count), x fastest, which must hold mesh_slab_planes(frame.size.z, z_begin, z_end,
// options.algorithm). Runs on voxfield's pool. Throws what mesh_volume throws (a NaN or infinite
// sample is named by its place in the whole lattice), and InvalidArgument for options mesh_slab
// does not apply to, a slab outside the lattice or planes that do not cover what it reads.
MeshSlab mesh_slab(const ScalarVolume& frame, int planes_z0, int plane_count, const float* planes,
                   const MeshOptions& options, int z_begin, int z_end);

// The same for a voxel world's surface at iso 0: the rows [z_begin, z_end) of mesh_world(world,
// options, metric)'s lattice, whose box is `lattice` — the world's content bounds grown by
// mesh_world_margin(0), as mesh_world takes them (a program holding part of the world learns them
// from every part: mpi::content_bounds). The slab computes the world's exact signed field over the
// planes it reads from the voxels within its clamp of them, so `world` needs to hold only the
// z-slices mesh_world_slab_voxels names (a bounded world of those slices will do; beyond a bounded
// world's bounds is air, as for mesh_world). The part's vertices are coloured from the world's
// palette and placed in its frame: consecutive slabs laid end to end are mesh_world's mesh, array
// for array. InvalidArgument for an offset surface (options.iso != 0: its normals come from the
// nearest voxels, which may lie anywhere), an analytic value or gradient, a lattice under 2
// samples along an axis, or a slab outside it; what mesh_world throws otherwise.
MeshSlab mesh_world_slab(const World& world, const Box3i& lattice, const MeshOptions& options,
                         Metric metric, int z_begin, int z_end);
// The world's slices [first, second) (world z, within the lattice) mesh_world_slab reads for the
// rows [z_begin, z_end) of `lattice`.
std::pair<int, int> mesh_world_slab_voxels(const Box3i& lattice, int z_begin, int z_end,
                                           Mesher mesher = Mesher::kMarchingCubes);
// How many slices beyond its rows, at most, on either side: the planes mesh_slab_planes adds and
// the field's clamp beyond them (6 for every mesher).
int mesh_world_slab_reach(Mesher mesher = Mesher::kMarchingCubes);

}  // namespace voxfield
