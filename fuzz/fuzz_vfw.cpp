// libFuzzer harness for the .vfw reader. Every section carries a CRC-32, so random mutations
// would almost never get past the checksums: the harness recomputes them first (where the
// section sizes allow) and so fuzzes the parser beneath them. Any input must parse or throw
// voxfield::Error; whatever parses must encode and parse back.
#include <zlib.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "fuzz_common.h"
#include "voxfield/world_file.h"

namespace {

std::uint32_t crc(const std::uint8_t* p, std::size_t n) {
  return static_cast<std::uint32_t>(crc32(0, p, static_cast<uInt>(n)));
}

// Rewrites the header checksum and every section checksum that lies within the input.
void fix_checksums(std::vector<std::uint8_t>& b) {
  if (b.size() < 20) return;
  const std::uint32_t h = crc(b.data(), 16);
  std::memcpy(b.data() + 16, &h, 4);
  std::size_t at = 20;
  while (at + 12 <= b.size()) {
    std::uint64_t size;
    std::memcpy(&size, b.data() + at + 4, 8);
    if (size > b.size() - at - 12 || b.size() - at - 12 - size < 4) return;
    const std::uint32_t c = crc(b.data() + at + 12, static_cast<std::size_t>(size));
    std::memcpy(b.data() + at + 12 + size, &c, 4);
    at += 12 + static_cast<std::size_t>(size) + 4;
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> bytes(data, data + size);
  fix_checksums(bytes);
  try {
    const voxfield::WorldFile f = voxfield::parse_world_file(bytes, "fuzz.vfw");
    std::vector<const voxfield::DistanceField*> fields;
    for (const auto& field : f.fields) fields.push_back(&field);
    const voxfield::WorldFile back = voxfield::parse_world_file(
        voxfield::encode_world_file(f.world, fields), "fuzz-reencoded.vfw");
    if (back.world.solid_count() != f.world.solid_count() || back.fields.size() != f.fields.size())
      std::abort();
  } catch (const voxfield::Error&) {
  }
  return 0;
}
