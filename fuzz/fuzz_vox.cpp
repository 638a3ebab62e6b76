// libFuzzer harness for the .vox reader: any input must parse or throw voxfield::Error.
#include <cstddef>
#include <cstdint>

#include "voxfield/vox.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const voxfield::VoxImport in = voxfield::parse_vox({data, size}, "fuzz.vox");
    // Whatever parsed must also encode and parse back.
    (void)voxfield::parse_vox(voxfield::encode_vox(in.world), "fuzz-reencoded.vox");
  } catch (const voxfield::Error&) {
  }
  return 0;
}
