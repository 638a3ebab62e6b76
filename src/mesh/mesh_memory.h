// voxfield — sizing a mesh's output arrays (internal to the mesh module).
//
// A mesh of millions of triangles is tens of megabytes written once: 14 000 faults on 4 KiB pages
// for the 256³ terrain's 2.3 M triangles (56 MB). On this project's virtual machine, perf of
// `voxfield mesh` put about a fifth of the command's samples in the kernel's page-fault path, and
// sizing the output (faults and zero-fill) still takes 16-18 ms beside 34-36 ms of writing on two
// threads with what follows (docs/benchmarks.md). So the arrays are reserved first (nothing touched
// yet), advised onto transparent huge pages (2 MiB, one fault for 512 small pages), touched once
// per page by all threads (the kernel zeroes each page on the thread that faults it), and only then
// sized — the vector's own zero-fill then runs over resident memory.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "voxfield/parallel.h"

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace voxfield::detail::mesh {

// v becomes n value-initialised (zero) elements.
template <class T>
void resize_on_huge_pages(std::vector<T>& v, std::size_t n) {
  v.clear();
  v.reserve(n);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
  const std::uintptr_t end = begin + n * sizeof(T);
  const std::uintptr_t first = (begin + kHuge - 1) / kHuge * kHuge, last = end / kHuge * kHuge;
  if (last > first)  // advice only: where it is refused the pages stay small
    madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#endif
  // The storage is allocated but holds no objects yet (v is empty): writing its bytes is allowed.
  auto* bytes = reinterpret_cast<unsigned char*>(v.data());
  const std::size_t size = n * sizeof(T);
  constexpr std::size_t kPage = 4096, kPagesPerTask = 512;
  if (size >= 4 * kPagesPerTask * kPage)
    parallel_for((size + kPage - 1) / kPage, kPagesPerTask,
                 [&](std::size_t begin, std::size_t end) {
                   for (std::size_t page = begin; page < end; ++page) bytes[page * kPage] = 0;
                 });
  v.resize(n);
}

}  // namespace voxfield::detail::mesh
