// voxfield programs and the Python module — refuse to run on a CPU without the instructions the
// build was compiled for.
//
// The build targets an x86-64 microarchitecture level (VOXFIELD_X86_64_LEVEL, x86-64-v2 by
// default: CMakeLists.txt says why). Code compiled for it stops with SIGILL — "Illegal
// instruction", naming nothing — at the first such instruction on an older CPU. This file alone is
// compiled for plain x86-64. A program (VOXFIELD_CPU_CHECK_AT_START) checks from a constructor of
// priority 101, the first one user code may take: before the program's other initialisers (a
// build with shared libraries runs theirs first; they set up tables, not kernels) — the user reads
// what is missing and how to build for their CPU, and the program exits. The Python module asks
// voxfield_cpu_lacks_build_level() when it is imported and raises ImportError with the same words.
// The library never exits.
#include <unistd.h>

#include <cstring>
#include <initializer_list>

namespace {

// Whether the CPU has the level. GCC names the levels themselves; clang 14 does not, and gets the
// features that matter to the code (POPCNT and SSE4 for v2, AVX2/BMI2/FMA for v3, AVX-512 for v4).
bool has_level(const char* level) {
  __builtin_cpu_init();
#if defined(__clang__)
  const bool v2 = __builtin_cpu_supports("popcnt") && __builtin_cpu_supports("ssse3") &&
                  __builtin_cpu_supports("sse4.1") && __builtin_cpu_supports("sse4.2");
  const bool v3 = v2 && __builtin_cpu_supports("avx") && __builtin_cpu_supports("avx2") &&
                  __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                  __builtin_cpu_supports("fma");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                  __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512vl");
#else
  const bool v2 = __builtin_cpu_supports("x86-64-v2");
  const bool v3 = __builtin_cpu_supports("x86-64-v3");
  const bool v4 = __builtin_cpu_supports("x86-64-v4");
#endif
  if (std::strcmp(level, "x86-64-v2") == 0) return v2;
  if (std::strcmp(level, "x86-64-v3") == 0) return v3;
  if (std::strcmp(level, "x86-64-v4") == 0) return v4;
  return true;  // plain x86-64
}

constexpr const char* kMessage =
    "this build of voxfield targets the x86-64 level " VOXFIELD_X86_64_LEVEL
    ", whose instructions this CPU lacks (x86-64-v2 needs POPCNT, SSSE3 and SSE4.1/4.2; v3 adds "
    "AVX2, BMI2 and FMA; v4 AVX-512); to run here, rebuild with cmake "
    "-DVOXFIELD_X86_64_LEVEL=x86-64";

#if defined(VOXFIELD_CPU_CHECK_AT_START)
__attribute__((constructor(101))) void check_cpu_at_start() {
  if (has_level(VOXFIELD_X86_64_LEVEL)) return;
  // write(2), not iostreams: nothing else of the program (nor its standard streams) is set up yet.
  for (const char* p : {"voxfield: ", kMessage, "\n"}) {
    const ssize_t ignored = write(2, p, std::strlen(p));
    (void)ignored;
  }
  _exit(1);
}
#endif

}  // namespace

// Null when the CPU has the build's level, else why not and what to do.
extern "C" const char* voxfield_cpu_lacks_build_level() {
  return has_level(VOXFIELD_X86_64_LEVEL) ? nullptr : kMessage;
}
