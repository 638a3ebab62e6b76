// Tests that patch the bytes of a .vfw (a field, a count, a frame) and want only that patch to be
// wrong: the header's and every section's CRC-32 made right again.
#pragma once

#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <vector>

namespace voxfield::test {

inline void fix_world_file_checksums(std::vector<std::uint8_t>& b) {
  auto crc = [](const std::uint8_t* p, std::size_t n) {
    return static_cast<std::uint32_t>(crc32(0, p, static_cast<uInt>(n)));
  };
  std::uint32_t sections;
  std::memcpy(&sections, b.data() + 12, 4);
  const std::uint32_t h = crc(b.data(), 16);
  std::memcpy(b.data() + 16, &h, 4);
  std::size_t at = 20;
  for (std::uint32_t s = 0; s < sections; ++s) {
    std::uint64_t size;
    std::memcpy(&size, b.data() + at + 4, 8);
    const std::uint32_t c = crc(b.data() + at + 12, static_cast<std::size_t>(size));
    std::memcpy(b.data() + at + 12 + size, &c, 4);
    at += 12 + static_cast<std::size_t>(size) + 4;
  }
}

}  // namespace voxfield::test
