// voxfield — whole-file reads and atomic writes, used by every reader and writer.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

namespace voxfield {

// Reads a whole file. Throws IoError naming the file when it cannot be opened or read, or when it
// is larger than `max_bytes`.
std::vector<std::uint8_t> read_file(const std::filesystem::path& path,
                                    std::uint64_t max_bytes = std::uint64_t{1} << 36);

// Replaces `path` with `bytes` atomically: writes a temporary file in the same directory, fsyncs
// it, renames it over `path` and fsyncs the directory. A crash or kill at any moment leaves either
// the old file or the new one, never a mix. Throws IoError (removing the temporary) on failure.
void write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

}  // namespace voxfield
