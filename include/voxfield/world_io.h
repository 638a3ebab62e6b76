// voxfield — loading and saving worlds by file type, shared by every front end (CLI, demo,
// Python): .vox (MagicaVoxel), .npy (NumPy: non-zero = that material) and .vfw (voxfield's world
// file) and .vdb (OpenVDB; vdb.h says which grid and voxels make the world). The type comes from
// the extension; the file's magic is checked against it before the rest of the file is read, so a
// mislabelled 256 MiB file is refused after 8 bytes.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/vox.h"
#include "voxfield/world.h"

namespace voxfield {

enum class WorldFormat { kVox, kNpy, kVfw, kVdb };

// The format named by a path's extension (case-insensitive). Throws InvalidArgument naming the
// path for anything else.
WorldFormat world_format_of(const std::filesystem::path& path);
const char* world_format_name(WorldFormat f);  // "vox", "npy", "vfw", "vdb"

struct LoadOptions {
  // Of the returned world; 0: a .vfw keeps the edge it was saved with, other files get 32.
  int chunk_edge = Grid<std::uint8_t>::kDefaultChunkEdge;
  std::uint64_t memory_limit_bytes = 0;  // 0: the process default (limits.h)
  // A .vdb file's grid to read the world from, by name; empty: world_from_vdb's rule (vdb.h).
  // Other formats refuse a name (InvalidArgument): they hold one world.
  std::string vdb_grid;
};

// A world read from any supported file, with what the file said about itself.
struct LoadedWorld {
  World world;
  WorldFormat format = WorldFormat::kVox;
  // The volume the file declares: the .npy shape, the visible instances' boxes or the model's
  // SIZE for .vox, the bounds (or else the content) for .vfw; always united with the content.
  Box3i extent;
  std::string description;            // one line: format, version, dtype...
  std::optional<VoxFileInfo> vox;     // .vox only
  std::vector<DistanceField> fields;  // .vfw only: the fields saved with the world
};

// Throws FormatError / IoError / ResourceLimitError naming the file.
LoadedWorld load_world(const std::filesystem::path& path, const LoadOptions& options = {});

// The world in chunks of another edge and other bounds (Grid::rechunked), after counting what the
// copy will allocate against the memory limit (0: the process default): a target chunk is dense
// unless it lies inside one uniform source chunk. Throws ResourceLimitError naming `who`.
World rechunk_world(const World& world, int chunk_edge, std::optional<Box3i> bounds,
                    const std::string& who, std::uint64_t memory_limit_bytes = 0);

// The bytes of `world` in a format; for .npy the box `extent` united with the content is written
// (a 1^3 box when both are empty).
std::vector<std::uint8_t> encode_world(const World& world, const Box3i& extent, WorldFormat format);
// encode_world by the path's extension, then write_file_atomic.
void save_world(const World& world, const Box3i& extent, const std::filesystem::path& path);
// What a save of `world` to `path` leaves out, said for its user: "P keeps no frame; the world's
// (...) is left out (.vfw and .vdb keep it)" when the world has a frame other than the identity
// and the format (.vox, .npy) has nowhere to put it; empty otherwise. Not an error: the voxels are
// what those formats are for.
std::string frame_left_out(const World& world, const std::filesystem::path& path);

}  // namespace voxfield
