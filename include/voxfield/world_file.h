// voxfield — the durable world file (.vfw): a World and, optionally, distance fields, in a
// documented, versioned binary format with checksums (docs/formats.md).
//
// Saving is atomic (temporary file, fsync, rename): killing the process mid-save leaves the
// previous file intact. Corrupt, truncated or future-version files are rejected with FormatError.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/world.h"

namespace voxfield {

// The newest format version this build reads and writes: 2 added the world's frame (a world in
// the identity frame is still written as version 1).
inline constexpr std::uint32_t kWorldFileVersion = 2;

struct WorldFile {
  World world;
  std::vector<DistanceField> fields;
  std::uint32_t version = kWorldFileVersion;
  // The union of the boxes of the world's stored chunks that may hold anything but air (dense
  // ones, and uniform ones of a material), within the grid's bounds: where the world's content
  // lies, known from the chunk records alone — also for the chunks a keep_z read skips.
  Box3i stored_chunks_box;
};

struct WorldFileReadOptions {
  // Refuse (ResourceLimitError) a file whose chunks would decode to more; 0: the process default
  // (limits.h). Counted from the chunk headers before anything is decompressed.
  std::uint64_t memory_limit_bytes = 0;
  // A slab of the world: decode only the chunks that reach into z in [keep_z->first,
  // keep_z->second), and no distance field. Every checksum and every world chunk record is still
  // checked; the other chunks are never decompressed nor charged against the memory limit, and a
  // field section is checked by its checksum alone. An empty range decodes
  // no chunk: the palette, the grid's head (chunk edge, bounds) and the frame alone. (What
  // voxfield-mpi's ranks read: each holds the file's compressed bytes and its own slab.)
  std::optional<std::pair<std::int32_t, std::int32_t>> keep_z;
};

std::vector<std::uint8_t> encode_world_file(const World& world,
                                            const std::vector<const DistanceField*>& fields = {});
// Throws FormatError for a corrupt or malformed file: checksums, a coordinate, bound or domain
// outside the supported range (box.h), a chunk given twice, field options compute_distance_field
// would refuse (NaN or negative clamp, spacing <= 0, an inverted domain).
WorldFile parse_world_file(std::span<const std::uint8_t> bytes, const std::string& name,
                           const WorldFileReadOptions& options = {});

// A world file written in parts by writers that each hold a slab of the world (voxfield-mpi's
// ranks): the file is frame.head, every part's records in order, then frame.tail — byte for byte
// encode_world_file of the whole world (without fields) when the parts are the whole world's chunks
// cut at chunk z coordinates, in increasing z.
struct WorldFilePart {
  std::vector<std::uint8_t> records;  // the chunk records, in file order
  std::uint64_t chunks = 0;
  std::uint32_t crc = 0;  // CRC-32 of the records
};
struct WorldFilePartSummary {
  std::uint64_t chunks = 0, bytes = 0;
  std::uint32_t crc = 0;
};
struct WorldFileFrame {
  std::vector<std::uint8_t> head, tail;
};
// The records of the chunks of `voxels` whose chunk coordinate z lies in [chunk_z_begin,
// chunk_z_end).
WorldFilePart encode_world_file_part(const Grid<std::uint8_t>& voxels, std::int32_t chunk_z_begin,
                                     std::int32_t chunk_z_end);
// What precedes and follows the parts of a world with this palette, chunk edge, bounds and
// voxel frame (the frame section, when not the identity, is in the tail).
WorldFileFrame encode_world_file_frame(const Palette& palette, int chunk_edge,
                                       const std::optional<Box3i>& bounds,
                                       std::span<const WorldFilePartSummary> parts,
                                       const VoxelFrame& voxel_frame = {});

void write_world_file(const World& world, const std::filesystem::path& path,
                      const std::vector<const DistanceField*>& fields = {});
WorldFile read_world_file(const std::filesystem::path& path,
                          const WorldFileReadOptions& options = {});

}  // namespace voxfield
