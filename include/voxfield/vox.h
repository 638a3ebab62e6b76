// voxfield — MagicaVoxel .vox import and export.
//
// Import reads versions 150 and 200: SIZE/XYZI models, RGBA palettes (MagicaVoxel's default
// palette when absent), PACK, many models, the scene graph (nTRN/nGRP/nSHP with translations,
// rotations, nested groups and instances, frame 0 of animations), hidden nodes and layers (LAYR),
// and Teardown's zlib-compressed TDCZ models. Every other chunk (MATL, MATT, rOBJ, rCAM, NOTE,
// META, IMAP, rLIT, ...) is skipped after its size has been checked.
//
// Placement follows MagicaVoxel: a shape's voxel v (0 <= v < size) lands on
//   floor(T + R * (v - floor(size / 2) + 0.5))
// where R, T compose every nTRN from the root down. Files without a scene graph place model
// `frame` (default 0: the first animation frame) with its voxel v at world position v. Where
// instances overlap, the one visited later in the scene graph wins.
//
// Malformed files throw FormatError naming the file, the byte offset and what is wrong; nothing is
// ever read out of bounds, and absurd sizes are rejected before anything is allocated. What the
// file will cost (models, instances, the world chunks its voxels touch) is counted before it is
// allocated; past the memory limit the reader throws ResourceLimitError. Deliberate leniencies
// (docs/limits.md): any version from 150 up is read (the chunk container is self-describing and
// unknown chunks are skipped); bytes after the MAIN chunk are refused.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "voxfield/world.h"

namespace voxfield {

struct VoxModelInfo {
  Vec3i size;                    // SIZE chunk
  std::int64_t voxel_count = 0;  // voxels stored in the file for this model (XYZI count or TDCZ)
  bool compressed = false;       // stored as a TDCZ chunk
};

struct VoxInstanceInfo {
  int model = 0;        // index into VoxFileInfo::models
  Box3i world_box;      // where the model's SIZE box lands in the world
  bool hidden = false;  // hidden node or layer (not imported unless include_hidden)
  std::string name;     // nTRN "_name", if any
};

struct VoxFileInfo {
  int version = 0;
  std::vector<VoxModelInfo> models;
  std::vector<VoxInstanceInfo> instances;  // empty for files without a scene graph
  bool has_scene_graph = false;
  bool has_palette = false;                 // an RGBA chunk was present
  std::map<std::string, int> chunk_counts;  // every chunk id seen, with its count
};

struct VoxImportOptions {
  int chunk_edge = Grid<std::uint8_t>::kDefaultChunkEdge;
  bool include_hidden = false;  // also import hidden nodes and layers
  int frame = 0;                // model placed when the file has no scene graph
  // Refuse (ResourceLimitError) a file whose models, instances and world chunks would need more;
  // 0: the process default (limits.h).
  std::uint64_t memory_limit_bytes = 0;
  // Place only the voxels with keep_z->first <= z < keep_z->second (the world's chunks, and the
  // memory counted for them, are then those of that slab); the whole scene is still read and
  // described in VoxImport::info. A slab of a world for one rank of an MPI job (mpi.h).
  std::optional<std::pair<std::int32_t, std::int32_t>> keep_z;
};

struct VoxImport {
  World world;
  VoxFileInfo info;
};

// The volume a file declares: the visible instances' boxes united (hidden ones too when
// `include_hidden`), or for a file without a scene graph the placed model's SIZE box.
Box3i vox_extent(const VoxFileInfo& info, bool include_hidden = false, int frame = 0);

// Parses a .vox file held in memory; `name` is used in error messages.
VoxImport parse_vox(std::span<const std::uint8_t> bytes, const std::string& name,
                    const VoxImportOptions& options = {});
VoxImport read_vox(const std::filesystem::path& path, const VoxImportOptions& options = {});

// Encodes a world as a version-200 .vox: the content is cut into regions of at most 256^3 (the
// format's model limit), each non-empty region becomes a model placed by the scene graph
// (nTRN -> nGRP -> nTRN/nSHP per model, one layer), and the palette is written as RGBA.
// Importing the result reproduces the world voxel for voxel. An empty world gives a file with one
// empty 1^3 model.
std::vector<std::uint8_t> encode_vox(const World& world);
// encode_vox, then write_file_atomic.
void write_vox(const World& world, const std::filesystem::path& path);

}  // namespace voxfield
