// voxfield — marching cubes of a slab of sample planes, for programs that each hold only some
// planes of a lattice (the ranks of an MPI job: voxfield::mpi::mesh_volume and write_mesh_volume)
// and want the mesh one process makes of the whole lattice, array for array.
//
// mesh_volume meshes a whole lattice in Flying Edges' passes (src/mesh/flying_edges.cpp): every
// row of samples (y, z) owns a run of vertex numbers — its crossings, then the centre vertices of
// the cell row it starts — and every cell row a run of triangles, both in row order. A slab of
// sample planes [z_begin, z_end) therefore owns one run of vertices and one run of triangles, and
// its triangles use only its own vertices and those of the rows of plane z_end (the next slab's
// first rows). Given the planes around it, a slab computes all of them with the whole lattice's
// samples and arithmetic: consecutive slabs' owned vertices and triangles, laid end to end (each
// slab's vertex numbers shifted by the vertices of the slabs before), are mesh_volume's mesh bit
// for bit, whatever the cuts.
#pragma once

#include <cstdint>
#include <utility>

#include "voxfield/mesh.h"

namespace voxfield {

// Whether mesh_slab meshes with these options: marching cubes without an analytic value or
// gradient (what mesh_volume meshes in the whole-volume passes). The chunked pieces
// (mesh_pieces.h) serve the rest.
bool mesh_slab_applies(const MeshOptions& options);

// The sample planes [first, second) meshing the rows of planes [z_begin, z_end) reads: one
// before (the gradients' stencils) to three past (plane z_end's rows, whose vertices the slab's
// triangles use, with their own stencils), within the lattice's `samples_z` planes.
std::pair<int, int> mesh_slab_planes(int samples_z, int z_begin, int z_end);

struct MeshSlab {
  // The vertices of the rows of sample planes [z_begin, z_end) — the slab's own, in mesh_volume's
  // order — then those of plane z_end's rows (the next slab's first, none when z_end is the
  // lattice's last plane + 1); the triangles of the cells in planes [z_begin, z_end), numbered
  // within `part`. No colours.
  Mesh part;
  std::uint64_t owned_vertices = 0;
  // The first of them: the vertices of plane z_begin's rows, among which are all that the slab
  // before's triangles use.
  std::uint64_t first_plane_vertices = 0;
};

// Meshes the rows of sample planes [z_begin, z_end) of the lattice `frame` describes (its size,
// origin and spacing; frame.values is not read) from `planes`: the samples of planes [planes_z0,
// planes_z0 + plane_count), x fastest, which must hold mesh_slab_planes(frame.size.z, z_begin,
// z_end). Runs on voxfield's pool. Throws what mesh_volume throws (a NaN or infinite sample is
// named by its place in the whole lattice), and InvalidArgument for options mesh_slab does not
// apply to, a slab outside the lattice or planes that do not cover what it reads.
MeshSlab mesh_slab(const ScalarVolume& frame, int planes_z0, int plane_count, const float* planes,
                   const MeshOptions& options, int z_begin, int z_end);

}  // namespace voxfield
