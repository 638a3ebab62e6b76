// voxfield — the programmer-error tier: checks of voxfield's own invariants.
//
// Errors a caller can cause are reported by throwing voxfield::Error (error.h) in every build.
// VOXFIELD_ASSERT is for what no input can cause — a broken invariant inside voxfield, i.e. a bug:
// compiled in where VOXFIELD_ENABLE_ASSERTS is defined (the debug and asan-ubsan presets, so the
// whole test suite runs with them), compiled out otherwise (no cost in optimised builds). A failed
// assertion prints the condition and where it failed, then aborts: a bug is not an error to
// recover from, and stopping at once keeps the sanitizers' and debuggers' view of it.
#pragma once

#ifdef VOXFIELD_ENABLE_ASSERTS
#include <cstdio>
#include <cstdlib>

namespace voxfield::detail {
[[noreturn]] inline void assertion_failed(const char* condition, const char* file, int line,
                                          const char* function) {
  std::fprintf(stderr, "voxfield: internal invariant broken: %s (%s:%d, in %s)\n", condition, file,
               line, function);
  std::abort();
}
}  // namespace voxfield::detail

#define VOXFIELD_ASSERT(condition)    \
  ((condition) ? static_cast<void>(0) \
               : ::voxfield::detail::assertion_failed(#condition, __FILE__, __LINE__, __func__))
#else
// Not evaluated (the condition may be costly), but still compiled, so it cannot rot.
#define VOXFIELD_ASSERT(condition) static_cast<void>(sizeof(static_cast<bool>(condition)))
#endif
