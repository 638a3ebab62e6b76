// voxfield — reading one OpenVDB tree from a .vdb file (internal to voxfield_io; vdb.h is the
// interface, vdb_read.cpp the file around the trees).
#pragma once

#include <cstdint>
#include <optional>

#include "byte_reader.h"
#include "voxfield/vdb.h"

namespace voxfield::detail {

// OpenVDB's per-grid compression flags (io/Compression.h).
inline constexpr std::uint32_t kVdbCompressZip = 0x1;
inline constexpr std::uint32_t kVdbCompressActiveMask = 0x2;
inline constexpr std::uint32_t kVdbCompressBlosc = 0x4;

struct VdbTreeReading {
  std::uint32_t format_version = 0;
  std::uint32_t compression = 0;  // the grid's flags
  std::uint64_t memory_limit_bytes = 0;
  std::uint64_t* used_bytes = nullptr;  // what the file's trees hold so far, across grids
  std::optional<Box3i> clip;            // VdbReadOptions::clip
};

// Reads a tree's topology and then its buffers from `r` into `grid`, whose value type, component
// count, half-float flag and log2_dims are already set from its type name. Throws FormatError
// (through `r`) for malformed bytes, ResourceLimitError when the tree passes the memory limit.
void read_vdb_tree(ByteReader& r, VdbGrid& grid, const VdbTreeReading& how);

}  // namespace voxfield::detail
