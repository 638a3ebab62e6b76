// voxfield CLI — a scope in which the pages the calling thread frees stay its own, for its
// next allocations to take without the kernel's help.
//
// A page a program frees is handed back to the kernel after a while (jemalloc's decay), and a page
// it takes from the kernel is zeroed on its first write. `voxfield mesh` of a scan frees the .npy
// file's bytes just before it sizes the mesh: kept, those pages hold the mesh's first arrays, and
// marching cubes of the 301 x 370 x 316 MRI took 89.8 / 93.1 ms instead of 96.4 / 97.3, its peak
// 5-6 MB higher (docs/benchmarks.md). Kept for the whole run instead, `voxfield field` of a 256³
// volume peaked 100 MB higher for nothing: hence a scope, and a purge at its end. Where the program
// is built without jemalloc (VOXFIELD_JEMALLOC off, the sanitizer builds), the scope does nothing
// (freed_pages.cpp is not compiled).
#pragma once

#include <cstddef>

namespace voxfield::app {

#if defined(VOXFIELD_HAS_JEMALLOC)
class KeepFreedPages {
 public:
  KeepFreedPages();  // freed_pages.cpp
  ~KeepFreedPages();
  KeepFreedPages(const KeepFreedPages&) = delete;
  KeepFreedPages& operator=(const KeepFreedPages&) = delete;

 private:
  // jemalloc's management names of the arena's decay time and purge, looked up on entry: leaving
  // allocates nothing (it may run while a failed allocation unwinds).
  std::size_t decay_mib_[3] = {}, purge_mib_[3] = {};
  long decay_ms_ = 0;  // the arena's, restored on leaving
  bool set_ = false;
};
#else
class KeepFreedPages {
 public:
  KeepFreedPages() = default;
  KeepFreedPages(const KeepFreedPages&) = delete;
  KeepFreedPages& operator=(const KeepFreedPages&) = delete;
};
#endif

}  // namespace voxfield::app
