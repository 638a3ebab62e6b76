// voxfield-bench-stream: this machine's memory bandwidth, the bound a memory-bound transform cannot
// pass, measured the way McCalpin's STREAM does (arrays far larger than the caches, simple loops
// the compiler vectorises, the best of several runs) for the access patterns voxfield's passes
// make: a read-only sweep, a write-only fill, a copy, and an in-place read-modify-write (the exact
// transforms' slice pass reads each voxel's partial distance and writes the final one in place).
// Each kernel runs on 1 and on 2 threads (the array split in halves); bandwidth counts the bytes
// the program reads plus those it writes (not the cache's extra read of each written line; copy
// is glibc's memcpy, which at this size writes past the cache and has none).
//
// usage: voxfield-bench-stream [MIB] [RUNS]   (256 MiB per array, 7 runs)
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <thread>
#include <vector>

#include "bench_util.h"

namespace {

// Runs body(begin, end) over [0, n) split into `threads` equal parts, one thread per part.
void split(std::size_t n, int threads, const std::function<void(std::size_t, std::size_t)>& body) {
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t)
    pool.emplace_back(body, n * static_cast<std::size_t>(t) / static_cast<std::size_t>(threads),
                      n * static_cast<std::size_t>(t + 1) / static_cast<std::size_t>(threads));
  body(0, n / static_cast<std::size_t>(threads));
  for (std::thread& t : pool) t.join();
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t mib = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 256;
  const int runs = argc > 2 ? std::atoi(argv[2]) : 7;
  if (mib < 16 || mib > 8192 || runs < 1 || runs > 1000) {
    std::fprintf(stderr, "usage: voxfield-bench-stream [MIB 16..8192] [RUNS 1..1000]\n");
    return 2;
  }
  const std::size_t n = mib * (std::size_t{1} << 20) / sizeof(std::uint32_t);
  // Touched before timing: page faults are the fresh-output cost measured elsewhere
  // (bench/run_cli_bench.sh), not bandwidth.
  std::vector<std::uint32_t> a(n, 1), b(n, 2);
  std::atomic<std::uint64_t> sink{0};  // the sums, kept so the reads are not optimised away
  struct Kernel {
    const char* name;
    double bytes_per_element;  // read + written
    std::function<void(std::size_t, std::size_t)> body;
  };
  const std::vector<Kernel> kernels = {
      {"read (sum)", 4,
       [&](std::size_t i0, std::size_t i1) {
         std::uint64_t s = 0;
         for (std::size_t i = i0; i < i1; ++i) s += a[i];
         sink.fetch_add(s, std::memory_order_relaxed);
       }},
      {"write (fill)", 4,
       [&](std::size_t i0, std::size_t i1) { std::fill(b.begin() + i0, b.begin() + i1, 7u); }},
      {"copy", 8,
       [&](std::size_t i0, std::size_t i1) {
         std::memcpy(b.data() + i0, a.data() + i0, (i1 - i0) * sizeof(std::uint32_t));
       }},
      {"read-modify-write in place", 8,
       [&](std::size_t i0, std::size_t i1) {
         for (std::size_t i = i0; i < i1; ++i) b[i] = b[i] * 3 + 1;
       }},
  };
  std::printf(
      "| kernel | threads | best ms of %d | GB/s (bytes read + written) |\n|---|---|---|---|\n",
      runs);
  for (const Kernel& k : kernels)
    for (int threads : {1, 2}) {
      const voxfield::bench::Timing t =
          voxfield::bench::time_runs(runs, [&] { split(n, threads, k.body); });
      std::printf("| %s | %d | %.2f | %.1f |\n", k.name, threads, t.min_ms,
                  k.bytes_per_element * static_cast<double>(n) / (t.min_ms * 1e6));
    }
  return 0;
}
