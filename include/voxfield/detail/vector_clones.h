// voxfield — a second, AVX2 copy of a hot loop, chosen when the program is loaded.
//
// voxfield is compiled for x86-64-v2 by default (CMakeLists.txt: SSE4.2 and POPCNT), which gives
// the vectoriser two doubles or four 32-bit integers per instruction. A loop of independent work
// over whole rows can ask for a second copy compiled for x86-64-v3 (AVX2: twice as wide): GCC's
// target_clones emits both and an ifunc resolver, run as the program or library is loaded, picks
// the copy the CPU can run, so the same binary still runs on every CPU the build supports. The
// copies compute the same bits: IEEE division, square root, sum and product, and integer min, add
// and compare, do not depend on the vector width, and voxfield compiles with -ffp-contract=off, so
// the x86-64-v3 copy fuses no multiply-add (FMA is part of that level) the source does not write.
// The resolvers themselves use no SSE4 or POPCNT instruction, so apps/common/cpu_check.cpp still
// names a CPU below the build's level before anything else runs.
//
// Every translation unit must see the same expansion (the project compiles them all with one
// -march). Empty, so each function is compiled once, where it cannot or need not apply: clang
// (the ASan/UBSan and fuzzing builds), any sanitizer build (the resolvers run before a sanitizer's
// runtime has started), other processors, builds whose baseline already has AVX2
// (VOXFIELD_X86_64_LEVEL=x86-64-v3 or above, -march=native: the one copy is already as wide), and
// -DVOXFIELD_AVX2_CLONES=OFF, which CI's cpu-only build uses to run the test suite on the
// baseline copies (CI's machines, like the developers', have AVX2).
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__AVX2__) && \
    !defined(__SANITIZE_THREAD__) && !defined(__SANITIZE_ADDRESS__) &&                       \
    !defined(VOXFIELD_NO_AVX2_CLONES)
#define VOXFIELD_AVX2_CLONE __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define VOXFIELD_AVX2_CLONE
#endif
