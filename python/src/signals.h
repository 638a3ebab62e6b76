// Ctrl-C during voxfield's long calls from Python (shared by the extension's modules).
#pragma once

#include <pybind11/pybind11.h>

#include <atomic>
#include <optional>
#include <thread>
#include <utility>

#include "voxfield/interrupt.h"
#include "voxfield/parallel.h"

namespace voxfield::python {

// Ctrl-C during a long call (a transform, a mesh): the thread that called (it works on the
// transform's tasks too) takes the GIL when the transform asks whether to go on and lets Python run
// its signal handlers; a KeyboardInterrupt stops the transform (voxfield throws Cancelled, which
// reaches Python as voxfield.Cancelled, a KeyboardInterrupt). Other worker threads only read the
// flag.
class PythonSignals : public Interrupter {
 public:
  bool was_interrupted(int) override {
    if (std::this_thread::get_id() != caller_) return stop_.load(std::memory_order_relaxed);
    pybind11::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) {
      PyErr_Clear();  // voxfield's Cancelled, translated, takes its place
      stop_.store(true, std::memory_order_relaxed);
    }
    return stop_.load(std::memory_order_relaxed);
  }

 private:
  std::thread::id caller_ = std::this_thread::get_id();
  std::atomic<bool> stop_{false};
};

// f() with the GIL released (other Python threads run meanwhile) and voxfield's parallel work
// limited to `threads` threads (0: every core).
template <class F>
auto without_gil(int threads, F&& f) {
  const pybind11::gil_scoped_release release;
  std::optional<ThreadLimit> limit;
  if (threads > 0) limit.emplace(threads);
  return std::forward<F>(f)();
}

}  // namespace voxfield::python
