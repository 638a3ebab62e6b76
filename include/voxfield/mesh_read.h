// voxfield — reading triangle meshes: Wavefront OBJ, PLY (ASCII, binary little- and big-endian),
// STL (ASCII and binary) and OFF, for voxelisation and distance fields (mesh_voxelize.h).
//
// Polygons are split into fans of triangles; only positions and faces are kept (texture
// coordinates, normals, colours, materials, lines and points are skipped). STL repeats each corner
// in every facet: corners with identical coordinates are merged into one position. Every file is
// untrusted: counts are checked against the file's size before anything is allocated for them,
// every index against the vertices read, every coordinate for being finite.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>

#include "voxfield/mesh_voxelize.h"

namespace voxfield {

enum class MeshInputFormat { kObj, kPly, kStl, kOff };

// The format named by a path's extension (.obj, .ply, .stl, .off, any case), or nothing.
std::optional<MeshInputFormat> mesh_input_format_of(const std::filesystem::path& path);
const char* mesh_input_format_name(MeshInputFormat f);  // "obj", "ply", "stl", "off"

struct MeshReadOptions {
  std::uint64_t memory_limit_bytes = 0;  // 0: the process default (limits.h)
};

// Parses a whole file's bytes; `name` is used in messages. Throws FormatError naming the file and
// the byte offset of the problem, ResourceLimitError when the mesh would pass the memory limit.
TriangleMesh parse_mesh(std::span<const std::uint8_t> bytes, MeshInputFormat format,
                        const std::string& name, const MeshReadOptions& options = {});
// Reads a file by its extension; IoError for an unreadable file, InvalidArgument for an extension
// that is not a mesh format.
TriangleMesh read_mesh(const std::filesystem::path& path, const MeshReadOptions& options = {});

}  // namespace voxfield
