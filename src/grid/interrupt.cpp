// voxfield — Progress: an operation's finished work units, forwarded to its interrupter.
#include "voxfield/interrupt.h"

#include <algorithm>

namespace voxfield {

Progress::Progress(Interrupter* interrupter, std::string_view name, std::int64_t total_units)
    : interrupter_(interrupter), name_(name), total_(std::max<std::int64_t>(total_units, 1)) {
  if (interrupter_) {
    interrupter_->start(name_);
    if (interrupter_->was_interrupted(0)) cancelled_.store(true, std::memory_order_relaxed);
  }
}

Progress::~Progress() {
  if (interrupter_) interrupter_->end();
}

bool Progress::advance(std::int64_t units) {
  if (!interrupter_) return true;
  done_.fetch_add(units, std::memory_order_relaxed);
  return keep_going();
}

bool Progress::keep_going() {
  if (!interrupter_) return true;
  if (cancelled()) return false;
  const std::lock_guard lock(ask_);
  if (cancelled()) return false;
  // Read under the lock: the work done only grows, so successive questions never step back.
  const int percent = static_cast<int>(
      std::min<std::int64_t>(100, done_.load(std::memory_order_relaxed) * 100 / total_));
  if (interrupter_->was_interrupted(percent)) cancelled_.store(true, std::memory_order_relaxed);
  return !cancelled();
}

void Progress::throw_if_cancelled() const {
  if (cancelled()) throw Cancelled(name_ + ": cancelled");
}

}  // namespace voxfield
