// voxfield fuzz harnesses — what they share: a memory limit well below libFuzzer's RSS limit
// (2 GiB), so that an input whose decoded size would pass it is refused by the reader's own check
// (a ResourceLimitError, counted as handled) instead of being reported as an out-of-memory crash.
#pragma once

#include <cstdint>

#include "voxfield/limits.h"

namespace voxfield::fuzz {

inline void init_limits() {
  set_default_memory_limit(std::uint64_t{256} << 20);
}

}  // namespace voxfield::fuzz
