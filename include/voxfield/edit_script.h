// voxfield — edit scripts: one JSON object per line, each an Edit (voxfield/edit.h).
//
//   {"op": "place", "shape": "sphere", "center": [40, 12, 7], "radius": 6, "material": 3}
//
// ops: place, carve, paint. shapes and their keys: sphere (center, radius), box (min, max:
// integers, inclusive), rotated-box (center, half_extent, rotation_deg: optional, degrees about x
// then y then z), capsule (a, b, radius), stamp (file: a .vox/.npy/.vfw world, relative to the
// script's directory; offset: optional integers). "material" is an integer 1..255 (default 1) for
// place and paint, and may be omitted or 0 for carve. Coordinates are voxel units and must lie in
// the supported range (|c| < 2^29, box.h); radii and half extents are finite, 0..2^29.
//
// Everything is checked when the script is parsed, before any world is loaded: a line with an
// unknown op, shape or key, a missing key, a wrong type, a fractional material, a negative
// radius, box min > max, non-finite or out-of-range numbers is refused with FormatError naming
// the script, the byte offset of the line and "line N: what is wrong". Blank lines are skipped.
#pragma once

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "voxfield/edit.h"

namespace voxfield {

struct EditScriptOptions {
  std::filesystem::path base_dir;                          // where stamps' relative paths start
  int chunk_edge = Grid<std::uint8_t>::kDefaultChunkEdge;  // of loaded stamp models
  bool load_stamps = true;               // false: stamps keep a null model (syntax checks only)
  std::uint64_t memory_limit_bytes = 0;  // for stamp models; 0: the process default
  // When set, receives the file of every stamp (resolved against base_dir), loaded or not: the
  // inputs a command must not overwrite.
  std::vector<std::filesystem::path>* stamp_files = nullptr;
};

// One line (without its newline). Throws InvalidArgument saying what is wrong (no file or line:
// parse_edit_script adds them), or the loader's errors for a stamp's file.
Edit parse_edit_line(std::string_view line, const EditScriptOptions& options = {});

// A whole script held in memory; `name` is used in error messages.
std::vector<Edit> parse_edit_script(std::span<const std::uint8_t> text, const std::string& name,
                                    const EditScriptOptions& options = {});
// Reads the script (a regular file) and parses it; base_dir defaults to the script's directory.
std::vector<Edit> read_edit_script(const std::filesystem::path& path,
                                   EditScriptOptions options = {});

}  // namespace voxfield
