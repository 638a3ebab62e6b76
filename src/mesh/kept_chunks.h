// voxfield — the per-chunk meshes that MeshChunks and WorldMeshChunks keep between edits
// (internal to the mesh module; defined in mesh_chunks.cpp). Which chunks a change reaches follows
// from what a chunk reads: its cells' corners, one cell before it (the dual meshers' apron) and
// the gradient stencils around them — samples from three before its first cell to two past its
// last corner (dual contouring's one-sided differences reach two samples out).
#pragma once

#include <vector>

#include "chunked_mesh.h"
#include "voxfield/mesh.h"

namespace voxfield::detail::mesh {

struct KeptChunks {
  MeshOptions options;
  ChunkGrid grid{{2, 2, 2}, 2};
  std::vector<ChunkPart> parts;

  // Meshes every chunk of `lattice` (options.chunk_edge); the interrupter watches this first mesh
  // only (it is forgotten after).
  void mesh_all(const Lattice& lattice);
  // Re-meshes every chunk whose reads meet one of the `changed` sample boxes (clipped to the
  // lattice) and returns those chunks. The new meshes are built aside and swapped in after all of
  // them are built, so an exception changes nothing.
  std::vector<Vec3i> update(const Lattice& lattice, const std::vector<Box3i>& changed);
  // Chunk `c`'s own mesh; InvalidArgument naming `who` for a chunk outside the grid.
  Mesh chunk_mesh(Vec3i c, const char* who) const;
  // Every chunk welded.
  Mesh merged() const;
};

}  // namespace voxfield::detail::mesh
