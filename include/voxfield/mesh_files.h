// voxfield — writing meshes: PLY (binary little-endian: positions, normals, 8-bit RGB colours),
// Wavefront OBJ (positions, normals), binary STL (facets with their normals) and glTF 2.0 binary
// (.glb: positions, normals, colours, 32-bit indices, in one buffer).
//
// Positions are in the mesh's units; glTF readers take them as metres. Saving is atomic (the file
// is replaced whole or not at all, see file.h).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "voxfield/mesh.h"

namespace voxfield {

enum class MeshFormat { kPly, kObj, kStl, kGlb };

const char* mesh_format_name(MeshFormat f);  // "ply", "obj", "stl", "glb"
// From the extension (.ply, .obj, .stl, .glb, any case); InvalidArgument naming the path otherwise.
MeshFormat mesh_format_of(const std::filesystem::path& path);

std::vector<std::uint8_t> encode_mesh(const Mesh& mesh, MeshFormat format);
// Encodes in the format the extension names and writes atomically; IoError naming the path.
void write_mesh(const Mesh& mesh, const std::filesystem::path& path);

// A mesh file in sections, for programs that each hold some of a mesh's vertices and triangles
// and never bring them together (the ranks of an MPI job: mpi::write_mesh_volume). The file is
// encode_mesh_head(format, totals), then each section of mesh_file_sections(format, totals) in
// turn; a vertex section is its runs of vertices encoded in the order of their numbers, the
// triangle section its runs of triangles in theirs — the bytes encode_mesh writes for the whole
// mesh (it is written this way, one run per section).
struct MeshTotals {
  std::uint64_t vertices = 0, triangles = 0;
  bool colored = false;
  std::array<float, 3> lo{}, hi{};  // the positions' bounds (glTF records them); 0 when none
};
MeshTotals mesh_totals(const Mesh& mesh);

enum class MeshSection {
  kVertices,   // PLY: each vertex's position, normal and colour
  kPositions,  // OBJ and glTF: positions
  kNormals,    // OBJ and glTF: normals
  kColors,     // glTF: colours (linear RGBA, 16-bit)
  kTriangles,  // PLY faces, OBJ faces, STL facets, glTF indices
};
std::vector<MeshSection> mesh_file_sections(MeshFormat format, const MeshTotals& totals);

// Everything before the first section. InvalidArgument for a mesh the format cannot count (an STL
// past 2^32 - 1 triangles, a .glb past 4 GiB).
std::vector<std::uint8_t> encode_mesh_head(MeshFormat format, const MeshTotals& totals);

// Appends a run's encoding for `section`: a vertex section's run is vertices [first, end) of
// `part`; the triangle section's run is every triangle of `part`, its vertex i being vertex
// global[i] of the whole mesh (i itself when `global` is empty). InvalidArgument for a run past
// the part's vertices, arrays of unequal lengths, an index past the vertices, `global` not one
// number per vertex, or colours asked of a part without them.
void encode_mesh_section(MeshFormat format, MeshSection section, const Mesh& part,
                         std::size_t first, std::size_t end, std::span<const std::uint32_t> global,
                         std::vector<std::uint8_t>& out);

}  // namespace voxfield
