// voxfield CLI — the terminal progress bar.
#include "progress.h"

#include <unistd.h>

#include <cstdio>

namespace voxfield::cli {

TerminalProgress::TerminalProgress() : terminal_(::isatty(STDERR_FILENO) == 1) {}

void TerminalProgress::start(std::string_view name) {
  if (!terminal_) return;
  std::lock_guard lock(mutex_);
  name_ = name;
  started_ = Clock::now();
  visible_ = false;
}

void TerminalProgress::end() {
  if (!terminal_) return;
  std::lock_guard lock(mutex_);
  if (visible_) std::fprintf(stderr, "\r\033[K");  // clear the bar's line
  visible_ = false;
}

bool TerminalProgress::was_interrupted(int percent) {
  if (!terminal_) return false;
  const Clock::time_point now = Clock::now();
  std::unique_lock lock(mutex_, std::try_to_lock);  // a worker busy drawing: the others go on
  if (!lock.owns_lock()) return false;
  if (now - started_ < std::chrono::seconds(1) ||
      (visible_ && now - drawn_ < std::chrono::milliseconds(100))) {
    return false;
  }
  constexpr int kWidth = 30;
  const int filled = percent * kWidth / 100;
  std::fprintf(stderr, "\r%s [%.*s%*s] %3d%%", name_.c_str(), filled,
               "##############################", kWidth - filled, "", percent);
  std::fflush(stderr);
  drawn_ = now;
  visible_ = true;
  return false;
}

TerminalProgress* progress() {
  static TerminalProgress bar;
  return &bar;
}

}  // namespace voxfield::cli
