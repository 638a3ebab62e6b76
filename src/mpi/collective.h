// voxfield — agreement between the ranks of a collective operation (internal): every rank runs its
// part, then all learn whether any failed, so that a failure on one rank becomes the same
// RankError on all of them instead of a hang in the next collective call.
#pragma once

#include <mpi.h>

#include <chrono>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>

#include "voxfield/mpi.h"

namespace voxfield::mpi::detail {

// Milliseconds since `t0`.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Adds one collective call's time to the stats.
class CollectiveTimer {
 public:
  explicit CollectiveTimer(ExchangeStats* stats) : stats_(stats) {}
  ~CollectiveTimer() {
    if (stats_) {
      stats_->exchange_ms += ms_since(t0_);
      ++stats_->collectives;
    }
  }
  CollectiveTimer(const CollectiveTimer&) = delete;
  CollectiveTimer& operator=(const CollectiveTimer&) = delete;

 private:
  ExchangeStats* stats_;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

// Collective: returns when no rank failed (`error` empty everywhere); else every rank throws
// RankError with the lowest failing rank's message.
void agree(MPI_Comm comm, const std::string& error, ExchangeStats* stats);

// Runs fn() on this rank and agrees on the outcome (agree above): fn's result on success.
template <class Fn>
auto collectively(MPI_Comm comm, ExchangeStats* stats, Fn&& fn) {
  using R = std::invoke_result_t<Fn>;
  std::string error;
  if constexpr (std::is_void_v<R>) {
    try {
      fn();
    } catch (const RankError&) {
      throw;  // agreed on inside fn, by every rank
    } catch (const std::exception& e) {
      error = e.what();
    }
    agree(comm, error, stats);
  } else {
    std::optional<R> result;
    try {
      result.emplace(fn());
    } catch (const RankError&) {
      throw;  // agreed on inside fn, by every rank
    } catch (const std::exception& e) {
      error = e.what();
    }
    agree(comm, error, stats);
    return std::move(*result);
  }
}

// The text of an MPI error code.
std::string mpi_error_text(int code);

}  // namespace voxfield::mpi::detail
