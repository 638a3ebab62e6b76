// libFuzzer harness for the option strings users type: camera specifications, byte sizes
// (--memory-limit), metric, storage, algorithm, render view and skip names. The first byte picks
// the parser; any input must parse or throw voxfield::Error.
#include <cstddef>
#include <cstdint>
#include <string>

#include "voxfield/algorithms.h"
#include "voxfield/limits.h"
#include "voxfield/render.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (data[0] % 7) {
      case 0: {
        const voxfield::Camera c =
            voxfield::Camera::parse(text, voxfield::Box3i::from_size({64, 64, 32}), 1.5);
        (void)c.projector(16, 9);
        break;
      }
      case 1:
        (void)voxfield::parse_byte_size(text);
        break;
      case 2:
        (void)voxfield::parse_metric(text);
        break;
      case 3:
        (void)voxfield::parse_storage(text);
        break;
      case 4:
        (void)voxfield::parse_algorithm(text);
        break;
      case 5:
        (void)voxfield::parse_render_view(text);
        break;
      case 6:
        (void)voxfield::parse_skip_mode(text);
        break;
    }
  } catch (const voxfield::Error&) {
  }
  return 0;
}
