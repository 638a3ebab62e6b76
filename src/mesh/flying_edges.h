// voxfield — the meshers of a whole dense lattice in Flying Edges' passes (internal to the mesh
// module): marching cubes (flying_edges.cpp, which explains the passes) and the dual meshers
// (flying_dual.cpp).
//
// The chunked driver (chunked_mesh.h) meshes chunks into parts and welds them, which is what
// MeshChunks keeps between edits and what a terrain's chunk-by-chunk samples need. A whole dense
// volume meshed once needs neither: this path counts every row's vertices and triangles first,
// then writes each vertex and triangle once, straight into the output — no part, no weld, no hash.
// Its vertices are numbered by lattice row (every chunk edge and thread count gives the same
// arrays); the triangles, positions and normals are the chunked driver's, bit for bit.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "bit_rows.h"
#include "chunked_mesh.h"
#include "voxfield/interrupt.h"

namespace voxfield::detail::mesh {

// Whether a lattice can take this path: marching cubes over samples in one array, with crossings
// and normals from the samples (no analytic value or gradient, no per-vertex colour function).
bool flying_edges_applies(const Lattice& lattice, const MeshOptions& options);

class FlyingEdges {
 public:
  // Classifies and counts (the first two passes). Throws InvalidArgument for a NaN or infinite
  // sample (naming the first) or more vertices than 32-bit indices hold, ResourceLimitError when
  // the bookkeeping passes the memory limit, Cancelled when the interrupter asks.
  // `z_offset`: the lattice is planes [z_offset, z_offset + n.z) of a larger one (a slab of it,
  // mesh_slab.cpp), whose frame the positions, sources and messages are in — positions bit for
  // bit those of the whole lattice, normals too wherever the slab holds their gradients' stencils
  // (a plane either side of the edge's ends).
  FlyingEdges(const Lattice& lattice, Interrupter* interrupter, int z_offset = 0);
  std::size_t vertices() const { return vertices_; }
  std::size_t indices() const { return indices_; }
  // Writes the mesh into arrays of at least vertices() / indices() elements (out.colors is
  // ignored: this path has no colours; out.sources, when not null, gets each vertex's inside
  // sample). Throws Cancelled when the interrupter asks (the arrays then hold part of the mesh).
  void write(const WeldOutput& out) const;
  // The vertices and indices of the rows before sample plane z (0 <= z <= n.z).
  std::uint64_t vertices_before(int z) const;
  std::uint64_t indices_before(int z) const;
  // Writes the vertices of sample planes [z_begin, z_end)'s rows, numbered from
  // vertices_before(z_begin), and the triangles of cell planes [z_begin, triangles_end) (<= z_end)
  // from indices_before(z_begin): write() is write_planes(0, n.z, n.z, out).
  void write_planes(int z_begin, int z_end, int triangles_end, const WeldOutput& out) const;

 private:
  const Lattice& lattice_;
  // One operation for the interrupter from counting to writing: units are planes, 3 per plane.
  std::unique_ptr<Progress> progress_;
  std::unique_ptr<InsideBits> inside_;
  std::size_t words_ = 0;  // per bit row
  // Per sample row: its first vertex (the row's x-edge crossings, then its y-edge and z-edge
  // ones, then the centre vertices of the cell row it starts) and the three edge counts; per cell
  // row, its first index. One entry past the last row holds the totals.
  std::vector<std::uint64_t> first_vertex_, first_index_;
  std::vector<std::uint32_t> x_count_, y_count_, z_count_;
  std::size_t vertices_ = 0, indices_ = 0;
  int z_offset_ = 0;

  void count_plane(int z);
  // Plane z's rows, numbered from vertex `first_vertex` and index `first_index`; its cells'
  // triangles only when `triangles` (their centre vertices always: they are its rows' vertices).
  void write_plane(int z, std::uint64_t first_vertex, std::uint64_t first_index, bool triangles,
                   const WeldOutput& out) const;
};

// Whether a lattice can take the dual path: surface nets or dual contouring over samples in one
// array, crossings and normals from the samples.
bool flying_dual_applies(const Lattice& lattice, const MeshOptions& options);

// Surface nets and dual contouring of a whole dense lattice in the same passes (flying_dual.cpp):
// counted per row, then each cell's vertex and each crossed edge's quad written once, in place.
class FlyingDual {
 public:
  // Classifies and counts; throws as FlyingEdges does.
  FlyingDual(const Lattice& lattice, const MeshOptions& options);
  // A slab of a larger lattice (mesh_slab.cpp): `lattice` holds planes [z_offset, z_offset +
  // lattice.n.z) of a lattice of `whole_z` planes, in whose frame positions, sources, messages and
  // the rules at the faces are. Only the vertices of cell planes [slab_begin - 1, slab_end) (the
  // slab's own and, when there is one, the plane before, whose vertices its quads use) and the
  // quads of sample planes [slab_begin, slab_end) are counted and written, numbered from the first
  // of them (local plane numbers; the lattice must hold what they read: mesh_slab_planes).
  FlyingDual(const Lattice& lattice, const MeshOptions& options, int z_offset, int whole_z,
             int slab_begin, int slab_end);
  std::size_t vertices() const { return vertices_; }
  std::size_t indices() const { return indices_; }
  // As FlyingEdges::write.
  void write(const WeldOutput& out) const;
  // The vertices of the cell rows and the indices of the sample rows before local plane z.
  std::uint64_t vertices_before(int z) const;
  std::uint64_t indices_before(int z) const;

 private:
  const Lattice& lattice_;  // the planes held (the whole lattice, or a slab's)
  Lattice whole_;           // the lattice meshed: positions, sources, faces (values unused)
  int z_offset_ = 0;        // local plane z is plane z + z_offset_ of whole_
  // Local planes counted and written: cells' vertices in [cells_begin_, cells_end_), sample rows'
  // quads in [quads_begin_, quads_end_).
  int cells_begin_ = 0, cells_end_ = 0, quads_begin_ = 0, quads_end_ = 0;
  CellVertex place_;
  std::unique_ptr<Progress> progress_;  // units are planes, 4 per plane
  std::unique_ptr<InsideBits> inside_;
  std::size_t words_ = 0;
  Block block_;  // a view of the lattice, for the vertex placement
  // Per cell row (y + ny z): its first vertex (one per cell a quad reaches); per sample row: its
  // first index (two triangles per crossed edge starting on it that has four cells around it). One
  // entry past the last row holds the totals.
  std::vector<std::uint64_t> first_vertex_, first_index_;
  // Per cell row, as many words as a bit row: the cells quads reach (bit x: cell x has a vertex),
  // found while counting and read by both writing passes.
  std::vector<std::uint64_t> reached_;
  std::size_t vertices_ = 0, indices_ = 0;

  const std::uint64_t* reached(int y, int z) const;
  struct Masks;
  void quads(int y, int z, Masks& m) const;
  void cells(int y, int z, Masks& scratch, std::uint64_t* used) const;
  void count_plane(int z);
  void write_vertices(int z, const WeldOutput& out) const;
  void write_surface_nets_vertices(int z, const WeldOutput& out) const;
  void write_quads(int z, const WeldOutput& out) const;
};

// The one place the path is chosen: whole(plan) with the whole-volume plan for a lattice one of
// them applies to (FlyingEdges or FlyingDual, counted already), chunked() otherwise (terrains'
// chunk-by-chunk samples, analytic values and gradients, colours).
template <class Whole, class Chunked>
auto mesh_by_plan(const Lattice& lattice, const MeshOptions& options, Whole&& whole,
                  Chunked&& chunked) {
  if (flying_edges_applies(lattice, options))
    return whole(FlyingEdges(lattice, options.interrupter));
  if (flying_dual_applies(lattice, options)) return whole(FlyingDual(lattice, options));
  return chunked();
}

}  // namespace voxfield::detail::mesh
