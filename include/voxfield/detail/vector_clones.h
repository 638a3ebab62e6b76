// voxfield — a second, AVX2 copy of a hot loop, chosen when the program starts.
//
// voxfield is compiled for x86-64-v2 by default (CMakeLists.txt: SSE4.2 and POPCNT, so it runs on
// any x86-64 CPU since 2008-2011), which gives the vectoriser 2 doubles per instruction. A loop of
// independent floating-point work — divisions and square roots, four of them per instruction in
// AVX — can ask for a second copy compiled for x86-64-v3 (AVX2, Haswell and Zen onwards); the
// dynamic loader picks the copy the CPU runs (GCC's target_clones, an ifunc), so the same binary
// still runs everywhere. The results are the same bits in both copies: IEEE division, square
// root, sum and product round the same way at any vector width, and voxfield compiles with
// -ffp-contract=off, so neither copy fuses a multiply-add the source does not write.
//
// Empty where it cannot or need not apply: clang (voxfield's sanitizer and fuzzing builds, which
// are not measured), other processors, and builds whose baseline already has AVX2
// (VOXFIELD_X86_64_LEVEL=x86-64-v3 or above, -march=native), where the one copy is already as wide
// and a v3 clone could only be narrower than the baseline.
#pragma once

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(__AVX2__)
#define VOXFIELD_AVX2_CLONE __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define VOXFIELD_AVX2_CLONE
#endif
