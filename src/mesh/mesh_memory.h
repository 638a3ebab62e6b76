// voxfield — sizing a mesh's output arrays (internal to the mesh module).
//
// A mesh of millions of triangles is tens of megabytes written once. On 4 KiB pages every page
// of it costs a fault on first touch, and on a virtual machine a fault costs microseconds: for the
// 256³ terrain's 2.3 M triangles (56 MB) the faults took longer than meshing itself. So the
// arrays are reserved first (nothing touched yet), advised onto transparent huge pages (2 MiB, one
// fault for 512 small pages), and only then sized.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace voxfield::detail::mesh {

template <class T>
void resize_on_huge_pages(std::vector<T>& v, std::size_t n) {
  v.reserve(n);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const auto begin = reinterpret_cast<std::uintptr_t>(v.data());
  const std::uintptr_t end = begin + n * sizeof(T);
  const std::uintptr_t first = (begin + kHuge - 1) / kHuge * kHuge, last = end / kHuge * kHuge;
  if (last > first)  // advice only: where it is refused the pages stay small
    madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
#endif
  v.resize(n);
}

}  // namespace voxfield::detail::mesh
