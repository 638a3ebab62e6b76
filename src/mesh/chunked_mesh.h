// voxfield — what the meshers share (internal to the mesh module): the chunk partition of a
// sample lattice, a chunk's block of samples, the per-chunk output and the weld that joins chunks.
//
// Seams. Chunks partition the lattice's cells. Every vertex belongs to one lattice element (an
// edge for marching cubes, a cell for surface nets) and that element to one chunk, its owner. A
// chunk creates the vertices its triangles use; those of elements it does not own are computed the
// same way as their owner does (same samples, same arithmetic, same rounding) and are replaced by
// the owner's at the weld (or, where the owner has no triangle using it, by the first user's copy),
// so chunks meet without cracks and the mesh does not depend on the partition. The weld looks
// vertices up by element key only for the owned vertices a mesher marks `shared` (those on a chunk
// border a neighbour can reach), a few per cent of the total.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/mesh.h"

namespace voxfield::detail::mesh {

// The sampled field, with the inside convention folded in: s = sign * (value - iso) is negative
// inside and >= 0 outside (a sample exactly at iso counts as outside).
struct Lattice {
  Vec3i n;  // samples per axis (each >= 2)
  const float* values = nullptr;
  // Where the samples are not one dense array (values is null: a terrain field's chunks),
  // fill(region, out) writes the samples of `region`, x fastest; each chunk's block copies what
  // it reads. Called from worker threads at once.
  const std::function<void(const Box3i&, float*)>* fill = nullptr;
  // Vertex colours, when given: the colour of a vertex made from inside sample `index` (x
  // fastest), looked up as each chunk is meshed.
  const std::function<std::array<std::uint8_t, 3>(std::uint64_t index)>* color = nullptr;
  std::array<double, 3> origin{}, spacing{};
  double iso = 0;
  double sign = 1;
  // A voxel world's field: the surface is the union of the voxels' cubes, so every crossing lies
  // on the face between two voxel centres and its exact normal is its edge's axis (dual
  // contouring then rebuilds the cubes' edges and corners exactly).
  bool voxel_faces = false;
  // MeshOptions::gradient, when given: the value's gradient at a position in world units.
  const std::function<std::array<double, 3>(const std::array<double, 3>&)>* gradient = nullptr;
  // The outward normal there: the gradient of s (the value's, times sign).
  std::array<double, 3> exact_normal(const std::array<double, 3>& position) const {
    const auto g = (*gradient)(position);
    return {g[0] * sign, g[1] * sign, g[2] * sign};
  }
  // MeshOptions::value, when given.
  const std::function<double(const std::array<double, 3>&)>* value = nullptr;
  // Where along the edge from lattice point p (sample s0) to its neighbour along `axis` (s1) the
  // surface crosses, as a fraction: on the function itself when it can be evaluated, else by
  // interpolating the samples. A function of the edge alone, so every chunk finds the same point.
  double crossing(Vec3i p, int axis, double s0, double s1) const;
  std::size_t index(int x, int y, int z) const {
    return static_cast<std::size_t>(x) +
           static_cast<std::size_t>(n.x) *
               (static_cast<std::size_t>(y) +
                static_cast<std::size_t>(n.y) * static_cast<std::size_t>(z));
  }
};

struct ChunkGrid {
  Vec3i cells;  // n - 1 per axis
  int edge = 32;
  Vec3i count;  // chunks per axis
  ChunkGrid(Vec3i samples, int chunk_edge);
  std::int64_t total() const { return static_cast<std::int64_t>(count.x) * count.y * count.z; }
  Vec3i coord(std::int64_t i) const;
  Box3i cells_of(Vec3i chunk) const;  // the chunk's cells
  // The chunk coordinate along `axis` owning lattice coordinate v (a sample or a cell): the last
  // chunk also owns the samples on the lattice's upper face.
  int owner(int axis, int v) const;
};

// A chunk's view of the samples, from one sample before its cells to two past them (clamped to
// the lattice): the cells' corners plus the neighbours central differences read. Loading scans the
// rows once for their signs (and NaN); samples are then read in place — from the lattice's array,
// or, for a lattice that fills regions, from the block's copy of everything the chunk reads (three
// samples before its cells to two past their last corner: the dual meshers' apron and the
// one-sided differences).
class Block {
 public:
  // Loads the block for `cells`; false when no sample changes sign (the chunk has no surface).
  // Throws InvalidArgument for a NaN sample.
  bool load(const Lattice& lattice, const Box3i& cells);
  // Views a dense lattice's whole array (lattice.values): no copy and no scan, so row_signs() is
  // not available — for the whole-volume passes, which classify the samples themselves.
  void view(const Lattice& lattice);
  // Views planes [z_offset, z_offset + n) of `whole` (n as many as `planes` holds), read in the
  // whole lattice's coordinates and clamped at its faces: a slab of it (mesh_slab.h). Reads must
  // stay within the planes held.
  void view_planes(const Lattice& whole, const float* planes, int z_offset);
  // The value with the inside convention folded in (negative inside).
  float s_of(float value) const { return negate_ ? iso_ - value : value - iso_; }
  bool inside(float value) const { return negate_ ? value > iso_ : value < iso_; }
  float s(int x, int y, int z) const { return s_of(*row(x, y, z)); }
  // The raw samples of row (y, z) from x on (x fastest).
  const float* row(int x, int y, int z) const {
    return data_ + (base_ + x + sy_ * static_cast<std::ptrdiff_t>(y) +
                    sz_ * static_cast<std::ptrdiff_t>(z));
  }
  // Which signs row (y, z) holds over the block: bit 0 some sample inside, bit 1 some outside.
  std::uint8_t row_signs(int y, int z) const {
    return signs_[static_cast<std::size_t>(y - lo_.y) + dy_ * static_cast<std::size_t>(z - lo_.z)];
  }
  // Gradient of s at a sample (central differences; one-sided on the lattice's faces), per unit.
  std::array<double, 3> gradient(int x, int y, int z) const;
  // Gradient for Hermite data: per axis the one-sided difference from the smoother side (the side
  // whose second difference is smaller: essentially non-oscillatory, Harten & Osher 1987), so that
  // near a crease the estimate stays on one face instead of averaging across it. Reads up to two
  // samples away (clamped to the lattice).
  std::array<double, 3> one_sided_gradient(int x, int y, int z) const;

 private:
  const Lattice* lattice_ = nullptr;
  float iso_ = 0;
  bool negate_ = false;
  Vec3i lo_, hi_;
  std::size_t dy_ = 0;
  std::vector<std::uint8_t> signs_;
  // Sample (x, y, z) is data_[base_ + x + sy_ y + sz_ z].
  const float* data_ = nullptr;
  std::ptrdiff_t base_ = 0, sy_ = 0, sz_ = 0;
  std::vector<float> copy_;  // a filled lattice's samples
};

// One chunk's triangles over its own vertex numbering.
struct ChunkPart {
  std::vector<std::array<float, 3>> positions, normals;
  std::vector<std::uint64_t> keys;     // the vertex's lattice element
  std::vector<std::uint64_t> sources;  // the inside sample the vertex came from (colours)
  std::vector<std::array<std::uint8_t, 3>> colors;  // per vertex, when the lattice has colours
  std::vector<std::uint8_t> owned;   // 1: this chunk owns the element; 0: a neighbour does
  std::vector<std::uint8_t> shared;  // owned and possibly used by a neighbour
  std::vector<std::uint32_t> indices;
  void clear();
  std::uint32_t add(const std::array<double, 3>& position, std::array<double, 3> normal,
                    std::uint64_t key, std::uint64_t source, bool is_owned, bool is_shared);
};

// Joins the chunks' parts (in chunk order) into one mesh; `sources`, when given, receives each
// vertex's source sample. Throws InvalidArgument when the mesh needs more than 2^32 - 1 vertices.
Mesh weld(const std::vector<ChunkPart>& parts, std::vector<std::uint64_t>* sources);

// The weld in two steps (weld.cpp): the plan — every vertex's global number and the counts — and
// the writing, into any arrays of at least those counts.
struct WeldPlan {
  std::vector<std::vector<std::uint32_t>> global;  // per part: local vertex -> global
  std::vector<std::uint64_t> base, index_base;     // per part: first owned vertex, first index
  std::vector<std::pair<std::uint32_t, std::uint32_t>> orphans;  // (part, local), numbered last
  std::size_t vertices = 0, indices = 0;
  bool colored = false;  // the parts carry colours
};
WeldPlan plan_weld(const std::vector<ChunkPart>& parts);
struct WeldOutput {
  std::array<float, 3>* positions;
  std::array<float, 3>* normals;
  std::array<std::uint8_t, 3>* colors;  // null: not written
  std::uint32_t* indices;
  std::uint64_t* sources;  // null: not written
};
void write_weld(const WeldPlan& plan, const std::vector<ChunkPart>& parts, const WeldOutput& out);

// A mesh's arrays sized for `vertices` and `indices` (colours when `colored`, and `sources` when
// given), on huge pages, with the WeldOutput that writes into them. Throws ResourceLimitError when
// the arrays would pass the memory limit (voxfield/limits.h), before allocating any.
WeldOutput size_mesh(Mesh& mesh, std::uint64_t vertices, std::uint64_t indices, bool colored,
                     std::vector<std::uint64_t>* sources);

// Position of lattice point p + t along `axis` (t in [0, 1]) in the volume's frame.
inline std::array<double, 3> lattice_position(const Lattice& l, const std::array<double, 3>& p) {
  return {l.origin[0] + p[0] * l.spacing[0], l.origin[1] + p[1] * l.spacing[1],
          l.origin[2] + p[2] * l.spacing[2]};
}

// The meshers: fill `part` with the triangles of `chunk`'s cells. `block` holds its samples.
void marching_cubes_chunk(const Lattice& lattice, const ChunkGrid& grid, Vec3i chunk,
                          const Block& block, std::vector<std::int32_t>& scratch, ChunkPart& part);
// Where a dual mesher puts the vertex of a cell the surface crosses, in the cell's coordinates
// ([0, 1]^3 from its lowest corner), from the cell's eight s values (corner c at (c & 1, c >> 1 &
// 1, c >> 2 & 1)).
using CellVertex = std::array<double, 3> (*)(const Block& block, const Lattice& lattice, Vec3i cell,
                                             const double* v);
std::array<double, 3> surface_nets_vertex(const Block& block, const Lattice& lattice, Vec3i cell,
                                          const double* v);
std::array<double, 3> dual_contouring_vertex(const Block& block, const Lattice& lattice, Vec3i cell,
                                             const double* v);
void dual_grid_chunk(const Lattice& lattice, const ChunkGrid& grid, Vec3i chunk, const Block& block,
                     std::vector<std::int32_t>& scratch, ChunkPart& part, CellVertex place);
// A dual quad — the four cells around a crossed edge, counter-clockwise seen from the edge's +axis
// ((0,0), (1,0), (1,1), (0,1) in its two other axes' offsets) — as two triangles split along the
// shorter diagonal (distance2 between two vertices), turned over when the outside is towards
// -axis (in0: the edge's lower sample is inside): six indices written at `out`, returning the
// end. Written in place rather than returned as an array (the array came back through memory and
// its read stalled on the stores that wrote it), and picked from a table of the four orders rather
// than by branches or selects (which side is shorter, and which side of the edge is inside, are
// coin tosses on a noisy volume: GCC 12 compiled the selects into two branches that were
// mispredicted on every other quad).
template <class Distance2>
std::uint32_t* put_quad(std::uint32_t* out, std::uint32_t v00, std::uint32_t v10, std::uint32_t v11,
                        std::uint32_t v01, bool in0, Distance2&& distance2) {
  // Split along 00-11: (00, 10, 11), (00, 11, 01); along 10-01: (00, 10, 01), (10, 11, 01); both
  // turned over (second and third corners swapped) unless in0. Entries index {00, 10, 11, 01}.
  static constexpr std::uint8_t kOrder[4][6] = {
      {0, 3, 1, 1, 3, 2},  // along 10-01, turned over
      {0, 1, 3, 1, 2, 3},  // along 10-01
      {0, 2, 1, 0, 3, 2},  // along 00-11, turned over
      {0, 1, 2, 0, 2, 3},  // along 00-11
  };
  const bool along_00_11 = distance2(v00, v11) <= distance2(v10, v01);
  const std::uint32_t v[4] = {v00, v10, v11, v01};
  const std::uint8_t* order =
      kOrder[2 * static_cast<unsigned>(along_00_11) + static_cast<unsigned>(in0)];
  for (int k = 0; k < 6; ++k) out[k] = v[order[k]];
  return out + 6;
}

// A dual mesher's vertex of cell q: its position in the volume's frame, its normal (not yet unit
// length) and its colour source (the inside corner nearest it). Every dual path computes it here,
// so that chunks and whole-volume passes agree bit for bit.
struct DualVertex {
  std::array<double, 3> position, normal;
  std::uint64_t source;
};
// Without `with_source` the source is left 0 (the nearest-corner search skipped: no colours, no
// sources asked for).
DualVertex dual_cell_vertex(const Block& block, const Lattice& lattice, int qx, int qy, int qz,
                            CellVertex place, bool with_source);
// The same once the cell's s values `v` and the vertex's place in the cell (`mean`, what a
// CellVertex returns) are known, for a pass that places vertices itself.
DualVertex dual_vertex_at(const Lattice& lattice, int qx, int qy, int qz, const double* v,
                          const std::array<double, 3>& mean, bool with_source);
// dual_vertex_at's parts, for a pass that evaluates a row of cells at once.
// The gradient of the cell's trilinear interpolant at (u, w1, w2) in the cell, per world unit:
// along each axis the corner differences blended by the other two coordinates. Inline and free
// of branches, so that a loop over many cells vectorises.
inline std::array<double, 3> trilinear_gradient(const double* v, double u, double w1, double w2,
                                                const std::array<double, 3>& spacing) {
  const auto blend = [](double d00, double d10, double d01, double d11, double s, double t) {
    return (1 - s) * (1 - t) * d00 + s * (1 - t) * d10 + (1 - s) * t * d01 + s * t * d11;
  };
  return {blend(v[1] - v[0], v[3] - v[2], v[5] - v[4], v[7] - v[6], w1, w2) / spacing[0],
          blend(v[2] - v[0], v[3] - v[1], v[6] - v[4], v[7] - v[5], u, w2) / spacing[1],
          blend(v[4] - v[0], v[5] - v[1], v[6] - v[2], v[7] - v[3], u, w1) / spacing[2]};
}
// The normal where that gradient is zero (a saddle of the interpolant, e.g. two inside corners
// touching diagonally): away from the inside corners' mean, in world units.
std::array<double, 3> saddle_normal(const double* v, double u, double w1, double w2,
                                    const std::array<double, 3>& spacing);
// The colour source: the inside corner of cell q nearest (u, w1, w2), the lowest-numbered on a tie.
std::uint64_t nearest_inside_corner(const Lattice& lattice, int qx, int qy, int qz, const double* v,
                                    double u, double w1, double w2);
// A normal scaled to unit length in floats (+z where it has no direction): ChunkPart::add's rule,
// shared by the whole-volume passes. (Scaled by the length's inverse, as the GPU mesher's shader
// does it: one division, not three, in the surface nets' placing loop that divisions bound.)
inline std::array<float, 3> unit_normal(std::array<double, 3> normal) {
  const double length =
      std::sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]);
  if (length > 0 && std::isfinite(length)) {
    const double inverse = 1 / length;
    for (double& c : normal) c *= inverse;
  } else {
    normal = {0, 0, 1};  // no direction to be had (a perfectly symmetric cell): still unit length
  }
  return {static_cast<float>(normal[0]), static_cast<float>(normal[1]),
          static_cast<float>(normal[2])};
}
// unit_normal() of each of `count` normals, bit for bit, in a loop of its own: the square root
// and the division of one normal do not wait on the next normal's, which they do when each vertex
// is finished before the next is begun (the marching-cubes write pass, where they were a tenth of
// the time). Compiled twice (vector_clones.h): the same IEEE operations in either copy.
// The normals come as three arrays (x, y, z components), so that the loop vectorises.
void unit_normals(const double* x, const double* y, const double* z, std::size_t count,
                  std::array<float, 3>* out);

}  // namespace voxfield::detail::mesh
