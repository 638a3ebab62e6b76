// voxfield — triangle meshes of iso-surfaces: marching cubes, surface nets and dual contouring,
// per chunk and seamless.
//
// A mesher reads a scalar field sampled on a lattice (a ScalarVolume: a float volume, or the exact
// signed distance field of a World) and returns one indexed triangle mesh of the surface where the
// field crosses `iso`. A volume in one array is meshed in Flying Edges' passes (rows counted, then
// every vertex and triangle written once, in place, rows in parallel; vertices numbered by row);
// terrains and MeshChunks split the cells into chunks meshed in parallel, whose border vertices are
// computed the same way on both sides and welded. Either way the mesh has no cracks and no
// duplicate triangles, and its arrays do not depend on the chunk edge or the thread count.
//
// Conventions, for every mesher:
//  * triangles wind counter-clockwise seen from outside (the side the field marks as outside), so
//    their right-hand normals point out; `normals` are the field's normalised gradient, pointing
//    out;
//  * positions are in the volume's frame: sample (x, y, z) sits at origin + (x, y, z) * spacing;
//  * vertices are shared between the triangles that meet there (indexed mesh, no unreferenced
//    vertices). A surface inside the volume gives a closed mesh (no boundary edge); marching cubes
//    gives a closed oriented 2-manifold (every edge in exactly two triangles, traversed both ways:
//    mesh_stats() checks), while surface nets and dual contouring, which join all the sheets
//    crossing a cell into one vertex, have edges in four triangles where the surface pinches
//    within a cell.
// Algorithms: docs/meshing.md; each opens its source file with its paper.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/distance.h"
#include "voxfield/world.h"

namespace voxfield {

class Interrupter;

// A read-only view of a dense scalar volume: size.x * size.y * size.z samples, x fastest (the
// layout of NpyVolume and Grid::copy_to_dense). NaN samples are refused by the meshers.
struct ScalarVolume {
  Vec3i size;
  const float* values = nullptr;
  // Where sample (x, y, z) sits: origin + (x, y, z) * spacing (scikit-image's spacing convention).
  std::array<double, 3> origin_units{0, 0, 0};
  std::array<double, 3> spacing_units{1, 1, 1};

  std::int64_t count() const { return Box3i::from_size(size).volume(); }
  float at(int x, int y, int z) const {
    return values[static_cast<std::size_t>(x) +
                  static_cast<std::size_t>(size.x) *
                      (static_cast<std::size_t>(y) +
                       static_cast<std::size_t>(size.y) * static_cast<std::size_t>(z))];
  }
};

enum class Mesher {
  kMarchingCubes,   // Lorensen & Cline 1987; faces decided by Nielson & Hamann's asymptotic decider
  kSurfaceNets,     // Gibson 1998, the naive variant: one vertex per cell the surface crosses
  kDualContouring,  // Ju et al. 2002: surface nets' topology, vertices on the crossings' tangent
                    // planes
};
const char* mesher_name(Mesher m);  // "mc", "sn", "dc"
// "mc"/"marching-cubes", "sn"/"surface-nets", "dc"/"dual-contouring"; else InvalidArgument.
Mesher parse_mesher(const std::string& name);

struct MeshOptions {
  Mesher algorithm = Mesher::kMarchingCubes;
  double iso = 0;
  // Which side of iso is inside: values below it (the default, a signed distance field's
  // convention) or above it (density volumes, the thesis's positive-inside terrain).
  bool inside_above = false;
  // Cells per chunk edge (each chunk is meshed as one unit of parallel work), 2..256: for
  // terrains, MeshChunks, and volumes meshed through an analytic value or gradient. A volume in
  // one array is meshed in Flying Edges' passes, which do not use chunks.
  int chunk_edge = 32;
  Interrupter* interrupter = nullptr;  // progress per chunk or plane; cancelling throws Cancelled
  // The field's gradient at a position (in the volume's units), when the caller knows it (an
  // analytic model, csg_mesh.h): dual contouring's Hermite normals and every mesher's vertex
  // normals come from it instead of differences of the samples. Called from worker threads at
  // once; it must give the same answer for the same position every time (seamless chunks).
  std::function<std::array<double, 3>(const std::array<double, 3>& position_units)> gradient;
  // The field's value at a position, when the caller can evaluate it anywhere: each crossing on a
  // lattice edge is then found on the function itself (Illinois regula falsi), not by
  // interpolating the edge's two samples, so vertices lie on the surface. Same rules as gradient.
  std::function<double(const std::array<double, 3>& position_units)> value;
};

struct Mesh {
  std::vector<std::array<float, 3>> positions;
  std::vector<std::array<float, 3>> normals;        // one per position, unit length, pointing out
  std::vector<std::array<std::uint8_t, 3>> colors;  // one per position, or empty (no colours)
  std::vector<std::uint32_t> indices;  // three per triangle, counter-clockwise from outside

  std::size_t vertex_count() const { return positions.size(); }
  std::size_t triangle_count() const { return indices.size() / 3; }
};

// Meshes `volume` at options.iso. Throws InvalidArgument for options out of range, a volume
// smaller than 2 samples along an axis, a spacing or origin positions cannot hold as floats, NaN
// or infinite samples (naming the first), or more vertices than 32-bit indices hold;
// ResourceLimitError for a mesh whose arrays, or a partition into so many chunks that its
// bookkeeping, would pass the memory limit (limits.h), before allocating them (a volume meshed
// through chunks has built its chunks' parts by then; docs/limits.md); Cancelled when the
// interrupter asks.
Mesh mesh_volume(const ScalarVolume& volume, const MeshOptions& options);

// Caller-allocated outputs, in meshoptimizer's style: mesh_bound() gives how large the arrays must
// be for any field on a lattice of `samples` (the worst case: every lattice edge crossed, every
// cell in its largest case), so an application can allocate them once — or size GPU buffers
// without reading anything back — and mesh_volume_into() writes the mesh into them.
struct MeshBound {
  std::uint64_t vertices = 0, indices = 0;
};
// Marching cubes: one vertex per lattice edge plus the case table's centre vertices (at most two
// per cell), at most 12 triangles per cell; surface nets and dual contouring: one vertex per cell,
// one quad per lattice edge. InvalidArgument for a lattice under 2 samples along an axis.
MeshBound mesh_bound(Vec3i samples, Mesher algorithm);

struct MeshBuffers {
  std::span<std::array<float, 3>> positions, normals;
  std::span<std::array<std::uint8_t, 3>> colors;  // empty: colours are not written
  std::span<std::uint32_t> indices;
};
struct MeshCounts {
  std::size_t vertices = 0, indices = 0;  // the first `vertices` and `indices` entries were written
};
// mesh_volume() written into `out`: the same arrays, element for element. InvalidArgument naming
// the counts needed when an array is too small (nothing is written then); other errors as
// mesh_volume().
MeshCounts mesh_volume_into(const ScalarVolume& volume, const MeshOptions& options,
                            const MeshBuffers& out);

// Meshes a World through its exact signed distance field in `metric` (solid voxels read
// -(distance to air), air +(distance to solid), in voxels between centres; options.inside_above is
// ignored). Voxel (x, y, z) spans [x, x+1)^3 in world units, so its sample sits at its centre
// (x + 0.5, y + 0.5, z + 0.5).
//  * At options.iso = 0 (the default): the voxels' own surface, running between solid and air
//    voxel centres — the same for every metric — with crossings on the faces between centres and
//    exact axis normals. Vertex colours: the material of the solid voxel a vertex was made from
//    (an edge's solid end; a cell's solid corner nearest the vertex).
//  * At iso V with |V| >= 1: the offset surface V voxels out from the solid voxels' centres, or
//    (V < 0) inside the solid |V| voxels from the air voxels' centres, shaped by the metric's ball
//    — rounded (Euclidean), a box (Chebyshev), an octahedron (Manhattan) — with normals from the
//    field's gradient: a safety margin around an obstacle, a shell. Vertex colours: the material of
//    the nearest solid voxel.
// The domain is the content grown past the surface by two voxels of air (beyond a bounded world's
// bounds is air, so the surface closes there too). InvalidArgument for an iso that is not finite,
// beyond ±1000 voxels, or strictly between -1 and 1 other than 0 (the field steps from -1 to +1
// between a solid and an air centre). The mesh is placed in the world's frame (place_in_frame):
// in the identity frame, voxel coordinates as above; iso stays in voxels.
Mesh mesh_world(const World& world, const MeshOptions& options, Metric metric = Metric::kEuclidean);
// How many voxels of air mesh_world's lattice reaches past the content at `iso` (2 at iso 0;
// InvalidArgument for an iso mesh_world refuses): its lattice is the content box grown by this.
int mesh_world_margin(double iso);

// Moves a mesh made in voxel coordinates into `frame`'s world: positions by world_from_vox,
// normals by world_normal (unit, perpendicular to the placed surface). Winding is kept: a frame
// turns and scales, never mirrors. InvalidArgument for an invalid frame.
void place_in_frame(Mesh& mesh, const VoxelFrame& frame);

// What a mesh is, topologically and geometrically.
struct MeshStats {
  std::size_t vertices = 0, triangles = 0;
  std::size_t edges = 0;                 // distinct undirected edges
  std::size_t boundary_edges = 0;        // in one triangle only
  std::size_t nonmanifold_edges = 0;     // in three or more triangles
  std::size_t misoriented_edges = 0;     // shared by two triangles that traverse it the same way
  std::size_t degenerate_triangles = 0;  // a repeated vertex index
  // Every edge in exactly two triangles, traversed in opposite directions: closed and oriented.
  bool watertight() const {
    return triangles > 0 && boundary_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0;
  }
  std::int64_t euler_characteristic = 0;  // V - E + F (2 for a sphere, 0 for a torus)
  // Counts one distinct edge, used by `uses` triangles of which `forward` run from its lower
  // vertex to its upper one (the census of mesh_stats, and of meshes spread over programs).
  void count_edge(std::uint64_t uses, std::uint64_t forward) {
    ++edges;
    if (uses == 1)
      ++boundary_edges;
    else if (uses > 2)
      ++nonmanifold_edges;
    else if (forward != 1)
      ++misoriented_edges;
  }
  double area_units2 = 0;
  double signed_volume_units3 = 0;  // positive when the triangles face out (closed meshes only)
};
// Throws InvalidArgument for an index past the last vertex.
MeshStats mesh_stats(const Mesh& mesh);

}  // namespace voxfield
