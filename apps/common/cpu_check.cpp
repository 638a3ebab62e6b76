// voxfield programs — refuse to start on a CPU without the instructions the build was compiled for.
//
// The build targets an x86-64 microarchitecture level (VOXFIELD_X86_64_LEVEL, x86-64-v2 by
// default: CMakeLists.txt says why). Code compiled for it stops with SIGILL — "Illegal
// instruction", naming nothing — at the first such instruction on an older CPU. This file alone is
// compiled for plain x86-64 and checks the CPU from a constructor that runs before any other
// initialiser of the program (priority 101, the first one user code may take), so the user reads
// what is missing and how to build for their CPU instead. The library never exits; a program may.
#include <unistd.h>

#include <cstring>

namespace {

// The features each level adds (GCC's names for __builtin_cpu_supports), cumulatively.
bool has_level(const char* level) {
  __builtin_cpu_init();
  const bool v2 = __builtin_cpu_supports("popcnt") && __builtin_cpu_supports("ssse3") &&
                  __builtin_cpu_supports("sse4.1") && __builtin_cpu_supports("sse4.2");
  const bool v3 = v2 && __builtin_cpu_supports("avx") && __builtin_cpu_supports("avx2") &&
                  __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2") &&
                  __builtin_cpu_supports("fma");
  const bool v4 = v3 && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                  __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512dq") &&
                  __builtin_cpu_supports("avx512vl");
  if (std::strcmp(level, "x86-64-v2") == 0) return v2;
  if (std::strcmp(level, "x86-64-v3") == 0) return v3;
  if (std::strcmp(level, "x86-64-v4") == 0) return v4;
  return true;  // plain x86-64
}

__attribute__((constructor(101))) void check_cpu() {
  if (has_level(VOXFIELD_X86_64_LEVEL)) return;
  // write(2), not iostreams: nothing else of the program (nor its standard streams) is set up yet.
  const char* parts[] = {
      "voxfield: this program was built for the x86-64 level ", VOXFIELD_X86_64_LEVEL,
      ", whose instructions this CPU lacks (x86-64-v2 needs POPCNT, SSSE3 and "
      "SSE4.1/4.2; v3 adds AVX2, BMI2 and FMA; v4 AVX-512); to run here, rebuild "
      "with cmake -DVOXFIELD_X86_64_LEVEL=x86-64\n"};
  for (const char* p : parts) {
    const ssize_t ignored = write(2, p, std::strlen(p));
    (void)ignored;
  }
  _exit(1);
}

}  // namespace
