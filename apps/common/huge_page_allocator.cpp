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
