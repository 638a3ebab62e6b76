// voxfield — a mesh built in pieces by programs that each hold only some sample planes of a
// lattice (the ranks of an MPI job: voxfield::mpi::mesh_volume, voxfield-mpi mesh), then joined.
//
// The chunked mesher (mesh_chunks.h) cuts the lattice's cells into chunks of `chunk_edge` cells;
// here its chunks are grouped into layers along z (layer k: the cells with k * edge <= z <
// (k + 1) * edge). A piece is the chunks of a run of layers, meshed from only the sample planes
// those chunks read (mesh_layer_planes: three before their cells to two past their last corner —
// the corners, the dual meshers' apron, the gradients' stencils), in the lattice's own frame: its
// vertices are computed with the same samples and the same arithmetic as when the whole lattice
// is meshed at once. Joining the pieces of every layer welds their border vertices as the chunked
// mesher welds its chunks, so the joined mesh equals MeshChunks(volume, options).merged() array
// for array — and mesh_volume(volume, options) triangle for triangle (its whole-volume pass numbers
// the same vertices by lattice row) — whatever the cut.
//
// A piece travels as bytes (to the rank that joins). Joining checks them as it would a file: a
// piece truncated, malformed, of another lattice or options, or overlapping another, or a layer
// missing, is refused by name.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <utility>
#include <vector>

#include "voxfield/mesh.h"

namespace voxfield {

namespace detail::mesh {
struct PieceParts;
}

// Chunk layers of a lattice of `samples` (each axis >= 2) cut into chunks of `chunk_edge` cells:
// ceil((samples.z - 1) / chunk_edge).
int mesh_chunk_layers(Vec3i samples, int chunk_edge);

// The sample planes [first, second) that meshing chunk layers [first_layer, end_layer) reads.
// InvalidArgument for an empty or out-of-range run of layers.
std::pair<int, int> mesh_layer_planes(Vec3i samples, int chunk_edge, int first_layer,
                                      int end_layer);

// Meshes chunk layers [first_layer, end_layer) of the lattice `frame` describes (its size, origin
// and spacing; frame.values is not read) from `planes`: the samples of planes [planes_z0,
// planes_z0 + plane_count), x fastest, which must hold mesh_layer_planes of those layers. Options
// as for mesh_volume (options.chunk_edge cuts the layers); the meshing runs on voxfield's pool.
// Returns the piece's bytes. Throws what mesh_volume throws (a NaN sample is named by its place in
// the whole lattice), and InvalidArgument when the planes do not cover what the layers read.
std::vector<std::uint8_t> mesh_piece(const ScalarVolume& frame, int planes_z0, int plane_count,
                                     const float* planes, const MeshOptions& options,
                                     int first_layer, int end_layer);

// Joins pieces that together cover every chunk layer once, in any order: the whole mesh (see
// above). Throws InvalidArgument naming the piece (its position in `pieces`) and the cause for a
// malformed piece, pieces of different lattices or options, overlapping or missing layers, or
// more vertices than 32-bit indices hold; ResourceLimitError past the memory limit.
Mesh join_mesh_pieces(const std::vector<std::span<const std::uint8_t>>& pieces);

// One piece's share of the joined mesh, for programs that never bring the pieces together (the
// ranks of an MPI job writing one mesh file: voxfield::mpi::write_mesh_volume). The pieces of
// every layer, in layer order, each learning only from its neighbours (the nearest pieces before
// and after it), number their vertices and triangles as join_mesh_pieces numbers the joined
// mesh's:
//   1. PieceWeld(piece) welds the piece's own chunks. An exclusive scan of owned_vertices() over
//      the pieces in order gives each its first vertex number.
//   2. lend(first_vertex) to both neighbours: the vertices its end layers own that a chunk beside
//      them may use. borrow() what the neighbours lend.
//   3. orphan_keys() to the piece after: vertices it uses that no chunk owns (surface nets: a cell
//      only a neighbour's quads reach). Every piece claim_orphans(the piece before's keys; none
//      for the first): the piece before takes those it shares. An exclusive scan of
//      claimed_orphans(), plus every piece's owned vertices, gives each its first orphan number.
//   4. number_orphans(first_orphan) to the piece after, which borrow()s them.
// Then part() is a mesh of every vertex its triangles use — its owned vertices first (numbered
// from first_vertex), its claimed orphans next (from first_orphan), then those of its neighbours —
// and its triangles (in the joined mesh's order, from its first chunk's); global() gives each of
// part()'s vertices its number in the joined mesh.
struct WeldKey {
  std::uint64_t key = 0;     // the vertex's lattice element
  std::uint64_t number = 0;  // its number in the joined mesh
};

class PieceWeld {
 public:
  // Checks the piece as join_mesh_pieces does (InvalidArgument naming the cause).
  explicit PieceWeld(std::span<const std::uint8_t> piece);
  // Meshes the piece as mesh_piece does (its arguments, what it throws), with no bytes between.
  PieceWeld(const ScalarVolume& frame, int planes_z0, int plane_count, const float* planes,
            const MeshOptions& options, int first_layer, int end_layer);
  ~PieceWeld();
  PieceWeld(PieceWeld&&) noexcept;
  PieceWeld& operator=(PieceWeld&&) noexcept;

  int first_layer() const;
  int end_layer() const;
  std::uint64_t owned_vertices() const;
  std::vector<WeldKey> lend(std::uint64_t first_vertex);
  // Resolves the vertices it uses that `keys` name (those it does not use are ignored).
  void borrow(std::span<const WeldKey> keys);
  std::vector<std::uint64_t> orphan_keys() const;
  void claim_orphans(std::span<const std::uint64_t> taken_before);
  std::uint64_t claimed_orphans() const;
  std::vector<WeldKey> number_orphans(std::uint64_t first_orphan);
  // InvalidArgument when a vertex is still unnumbered (a step missed) or a number passes 32 bits.
  Mesh part() const;
  std::vector<std::uint32_t> global() const;

 private:
  explicit PieceWeld(detail::mesh::PieceParts&& piece);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxfield
