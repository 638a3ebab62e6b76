// libFuzzer harness for the .npy reader: any input must parse or throw voxfield::Error; whatever
// parses must encode and parse back, and convert to a world or be refused with an Error.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz_common.h"
#include "voxfield/npy.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const voxfield::NpyVolume v = voxfield::parse_npy({data, size}, "fuzz.npy");
    const voxfield::NpyVolume back =
        voxfield::parse_npy(voxfield::encode_npy(v), "fuzz-reencoded.npy");
    if (back.bytes != v.bytes || !(back.dims == v.dims)) std::abort();
    (void)voxfield::world_from_npy(v, "fuzz.npy", 8);
  } catch (const voxfield::Error&) {
  }
  return 0;
}
