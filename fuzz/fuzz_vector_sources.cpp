// libFuzzer harness for the vector-field sources parser (voxfield vectors SOURCES.json): any input
// must parse or throw voxfield::Error; whatever parses is valid input for a small generation, which
// must not fail.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz_common.h"
#include "voxfield/vector_files.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  voxfield::VectorSourceFrames frames;
  try {
    frames = voxfield::parse_vector_sources({data, size}, "fuzz.json");
  } catch (const voxfield::Error&) {
    return 0;
  }
  voxfield::VectorVolume volume;
  volume.size = {8, 8, 8};
  volume.resolution = {8, 8, 8};
  try {
    voxfield::VectorSimulation sim(volume, voxfield::VectorStorage::kRgba8, {}, 1.0);
    for (const auto& frame : frames.frames) sim.step(frame, 1.0 / 60);
  } catch (const voxfield::Error&) {
    std::abort();  // the parser accepted sources that a generation refuses
  }
  return 0;
}
