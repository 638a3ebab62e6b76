// voxfield — progress and cancellation of long operations, in the manner of OpenVDB's
// util/NullInterrupter.h: whole distance transforms, rebuilds of incremental fields, renders and
// scene generation take an optional Interrupter*, tell it how far they are, and stop when it says
// so. A null interrupter costs nothing.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <string_view>

#include "voxfield/error.h"

namespace voxfield {

// An operation stopped because its interrupter asked it to. Nothing the operation was given has
// changed (its result, not yet returned, is discarded); the message names the operation.
class Cancelled : public Error {
 public:
  using Error::Error;
};

// Derive from this to watch and cancel long operations (a progress bar, an editor's Cancel
// button, a deadline). The defaults watch nothing and never cancel.
class Interrupter {
 public:
  virtual ~Interrupter() = default;
  // Once when an operation starts (`name`, e.g. "exact distance field") and once when it ends,
  // whether it finished, failed or was cancelled. Called on the thread that called the operation.
  virtual void start(std::string_view name) { static_cast<void>(name); }
  virtual void end() {}
  // Asked between units of work with how far the operation is (0..100). Return true to cancel:
  // the operation stops at its next check and throws Cancelled. Called from any of voxfield's
  // worker threads; one operation asks one question at a time, with percentages that never
  // decrease (a progress bar never steps back). Operations on several threads may share an
  // interrupter, so an implementation must still be thread-safe (an atomic flag is enough).
  virtual bool was_interrupted(int percent) {
    static_cast<void>(percent);
    return false;
  }
};

// One operation's progress over a known number of work units, reported to an interrupter. Work
// loops call advance() as units finish (from any thread) and skip remaining units once it returns
// false; the operation calls throw_if_cancelled() before it publishes anything.
class Progress {
 public:
  // Calls interrupter->start(name) (nothing when the interrupter is null).
  Progress(Interrupter* interrupter, std::string_view name, std::int64_t total_units);
  ~Progress();  // calls interrupter->end()
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Records `units` more finished. Returns false once the operation was cancelled (by this call's
  // question to the interrupter or an earlier one). Thread-safe.
  bool advance(std::int64_t units = 1);
  // Whether to go on, without recording work: false once cancelled. Thread-safe.
  bool keep_going();
  bool cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  // Throws Cancelled naming the operation when it was cancelled.
  void throw_if_cancelled() const;

 private:
  Interrupter* interrupter_;
  std::string name_;
  std::int64_t total_;
  std::atomic<std::int64_t> done_{0};
  std::atomic<bool> cancelled_{false};
  // Questions are asked one at a time, each with the work done when it is asked: without this,
  // a thread that computed 52 % could ask after one that computed 100 %.
  std::mutex ask_;
};

}  // namespace voxfield
