// voxfield — the durable world file (.vfw): a World and, optionally, distance fields, in a
// documented, versioned binary format with checksums (docs/formats.md).
//
// Saving is atomic (temporary file, fsync, rename): killing the process mid-save leaves the
// previous file intact. Corrupt, truncated or future-version files are rejected with FormatError.
#pragma once

#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/world.h"

namespace voxfield {

inline constexpr std::uint32_t kWorldFileVersion = 1;

struct WorldFile {
  World world;
  std::vector<DistanceField> fields;
  std::uint32_t version = kWorldFileVersion;
};

struct WorldFileReadOptions {
  // Refuse (ResourceLimitError) a file whose chunks would decode to more; 0: the process default
  // (limits.h). Counted from the chunk headers before anything is decompressed.
  std::uint64_t memory_limit_bytes = 0;
};

std::vector<std::uint8_t> encode_world_file(const World& world,
                                            const std::vector<const DistanceField*>& fields = {});
// Throws FormatError for a corrupt or malformed file: checksums, a coordinate, bound or domain
// outside the supported range (box.h), a chunk given twice, field options compute_distance_field
// would refuse (NaN or negative clamp, spacing <= 0, an inverted domain).
WorldFile parse_world_file(std::span<const std::uint8_t> bytes, const std::string& name,
                           const WorldFileReadOptions& options = {});

void write_world_file(const World& world, const std::filesystem::path& path,
                      const std::vector<const DistanceField*>& fields = {});
WorldFile read_world_file(const std::filesystem::path& path,
                          const WorldFileReadOptions& options = {});

}  // namespace voxfield
