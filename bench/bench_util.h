// voxfield benchmarks — timing and memory helpers shared by the bench programs.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace voxfield::bench {

struct Timing {
  double median_ms, min_ms, max_ms;
};

// Runs `fn` once to warm up, then `runs` times; returns median, min and max in milliseconds.
template <class Fn>
Timing time_runs(int runs, Fn&& fn) {
  fn();
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return {ms[ms.size() / 2], ms.front(), ms.back()};
}

// Reads a "Name:   1234 kB" line of /proc/self/status, in bytes.
inline std::size_t proc_status_bytes(const char* name) {
  std::ifstream f("/proc/self/status");
  std::string line;
  const std::string key = std::string(name) + ":";
  while (std::getline(f, line)) {
    if (line.rfind(key, 0) == 0) return std::stoull(line.substr(key.size())) * 1024;
  }
  return 0;
}

// Resets the peak resident set size (VmHWM) to the current one (Linux "clear_refs" 5).
inline void reset_peak_rss() {
  std::ofstream("/proc/self/clear_refs") << "5";
}

}  // namespace voxfield::bench
