// libFuzzer harness for the .npy reader: any input must parse or throw voxfield::Error.
#include <cstddef>
#include <cstdint>

#include "voxfield/npy.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const voxfield::NpyVolume v = voxfield::parse_npy({data, size}, "fuzz.npy");
    (void)voxfield::parse_npy(voxfield::encode_npy(v), "fuzz-reencoded.npy");
  } catch (const voxfield::Error&) {
  }
  return 0;
}
