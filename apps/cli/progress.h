// voxfield CLI — a progress bar on the terminal for long operations.
#pragma once

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

#include "voxfield/interrupt.h"

namespace voxfield::cli {

// Draws "name [#####     ]  42%" on stderr, once an operation has run for a second, when stderr
// is a terminal; silent otherwise (pipes, logs, CI). Redrawn at most ten times a second and cleared
// when the operation ends. Never cancels: Ctrl-C stops the CLI (with its outputs removed) through
// install_signal_cleanup.
class TerminalProgress : public Interrupter {
 public:
  TerminalProgress();
  void start(std::string_view name) override;
  void end() override;
  bool was_interrupted(int percent) override;

 private:
  using Clock = std::chrono::steady_clock;
  const bool terminal_;
  std::mutex mutex_;
  std::string name_;
  Clock::time_point started_{}, drawn_{};
  bool visible_ = false;
};

// The CLI's progress bar (one per process).
TerminalProgress* progress();

}  // namespace voxfield::cli
