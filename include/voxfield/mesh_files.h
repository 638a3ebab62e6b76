// voxfield — writing meshes: PLY (binary little-endian: positions, normals, 8-bit RGB colours),
// Wavefront OBJ (positions, normals), binary STL (facets with their normals) and glTF 2.0 binary
// (.glb: positions, normals, colours, 32-bit indices, in one buffer).
//
// Positions are in the mesh's units; glTF readers take them as metres. Saving is atomic (the file
// is replaced whole or not at all, see file.h).
#pragma once

#include <cstdint>
#include <filesystem>
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

}  // namespace voxfield
