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
// large enough to matter. oversize_threshold:0 serves large blocks (8 MiB and up) from the ordinary
// arenas, which keep freed pages for reuse for a while (dirty_decay_ms, 10 s), rather than from
// jemalloc's dedicated arena for them, which hands freed pages back to the kernel at once: a later
// large block, such as the mesh written after its input's raw bytes are dropped, then reuses pages
// already faulted in instead of faulting and zeroing new ones. `voxfield mesh` of the 256³
// terrain's field, marching cubes on one thread: 1880 page faults and 70 ms of meshing before,
// 1490 and 65 ms after (docs/benchmarks.md); the peak memory did not grow.
const char* malloc_conf = "thp:always,metadata_thp:auto,oversize_threshold:0";
