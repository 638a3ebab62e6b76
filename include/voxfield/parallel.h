// voxfield — the thread pool every parallel algorithm runs on.
//
// voxfield uses oneTBB's work-stealing scheduler (see docs/architecture.md for why) but keeps it
// out of its public headers: callers see only these functions.
#pragma once

#include <cstddef>
#include <functional>
#include <memory>

namespace voxfield {

// Runs body(begin, end) over disjoint sub-ranges covering [0, n), possibly concurrently. `grain` is
// the smallest range worth handing to another thread. Exceptions thrown by `body` propagate to the
// caller (the first one wins; the remaining work is cancelled).
void parallel_for(std::size_t n, std::size_t grain,
                  const std::function<void(std::size_t begin, std::size_t end)>& body);

// Number of threads parallel_for may use right now.
int max_threads();

// While alive, limits voxfield's parallel work to `threads` threads (>= 1). Limits nest; the
// smallest active one applies. Throws InvalidArgument for threads < 1.
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxfield
