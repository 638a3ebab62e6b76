// voxfield CLI — KeepFreedPages (freed_pages.h) through jemalloc's management interface. Compiled
// alone, and only into a CLI linked with jemalloc (CMakeLists.txt): jemalloc.h redeclares malloc
// and its family, which no other file of a unity batch should see.
#include "freed_pages.h"

#include <jemalloc/jemalloc.h>

namespace voxfield::app {

// The calling thread's arena keeps its dirty pages (decay -1: never purged) until the scope ends,
// then purges what is left and decays as before. Advice only: where a call fails, nothing changes.
KeepFreedPages::KeepFreedPages() {
  unsigned arena = 0;
  std::size_t size = sizeof arena;
  if (mallctl("thread.arena", &arena, &size, nullptr, 0) != 0) return;
  std::size_t decay_length = 3, purge_length = 3;
  if (mallctlnametomib("arena.0.dirty_decay_ms", decay_mib_, &decay_length) != 0 ||
      mallctlnametomib("arena.0.purge", purge_mib_, &purge_length) != 0)
    return;
  decay_mib_[1] = purge_mib_[1] = arena;
  ssize_t keep = -1, old = 0;
  size = sizeof old;
  if (mallctlbymib(decay_mib_, 3, &old, &size, &keep, sizeof keep) != 0) return;
  decay_ms_ = static_cast<long>(old);
  set_ = true;
}

KeepFreedPages::~KeepFreedPages() {
  if (!set_) return;
  ssize_t old = static_cast<ssize_t>(decay_ms_);
  (void)mallctlbymib(decay_mib_, 3, nullptr, nullptr, &old, sizeof old);
  // What the scope kept and no allocation took goes back to the kernel now, as it would have when
  // it was freed: what the scope adds to the peak is what the meshing itself took of it.
  (void)mallctlbymib(purge_mib_, 3, nullptr, nullptr, nullptr, 0);
}

}  // namespace voxfield::app
