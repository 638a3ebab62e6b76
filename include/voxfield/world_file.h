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

std::vector<std::uint8_t> encode_world_file(const World& world, const std::vector<const DistanceField*>& fields = {});
WorldFile parse_world_file(std::span<const std::uint8_t> bytes, const std::string& name);

void write_world_file(const World& world, const std::filesystem::path& path,
                      const std::vector<const DistanceField*>& fields = {});
WorldFile read_world_file(const std::filesystem::path& path);

}  // namespace voxfield
