// voxfield's programs (the CLI, the demo, voxfield-mpi) allocate through jemalloc with transparent
// huge pages. Why: a field's chunks are fresh memory, and the first write to each 4 KiB page is a
// page fault. On the machines we measure on (Debian 12 guests, THP in "madvise" mode) a first touch
// costs about 11 µs per 4 KiB page against about 0.3 ms per 2 MiB page, so `voxfield field` on a
// 256³ volume spent a sixth to a fifth of its transform and two fifths of its run faulting pages
// in: 77 800 faults with glibc's malloc, 3 300 with this (docs/benchmarks.md, "As a user runs
// them"). glibc's malloc can do the same only through GLIBC_TUNABLES=glibc.malloc.hugetlb=1, read
// from the environment at start-up; jemalloc reads the configuration below from the program itself.
//
// The library never chooses a process's allocator: applications linking libvoxfield keep theirs
// (docs/limits.md says how to get the same effect). MALLOC_CONF in the environment still applies
// on top of this, e.g. MALLOC_CONF=thp:default turns the huge pages off again.
#include <jemalloc/jemalloc.h>

#include "freed_pages.h"

// thp:always advises every mapping jemalloc makes for huge pages (the kernel then backs whole
// 2 MiB ranges at the first fault); metadata_thp:auto does so for its own metadata once that is
// large enough to matter. oversize_threshold:0 turns off jemalloc's dedicated arena for blocks of
// 8 MiB and more, so they come from the ordinary arenas. Measured, not derived: `voxfield mesh` of
// the 256³ terrain's field (marching cubes, one thread) faults 1 500 pages instead of 1 890 and
// meshes in 64-65 ms instead of 69-70; `perf record -e page-faults --call-graph dwarf` puts the
// faults saved in the first writes to the mesher's own bookkeeping (its bit rows and row counts),
// which now land in memory the run freed before. What it does not do: keep a freed block of 8 MiB
// or more for reuse on the main thread — Debian's jemalloc 5.3.0 gives arena 0 its own 8 MiB
// threshold for returning those to the kernel at once (strace shows the input's bytes returned
// either way). docs/benchmarks.md has the runs.
const char* malloc_conf = "thp:always,metadata_thp:auto,oversize_threshold:0";

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
