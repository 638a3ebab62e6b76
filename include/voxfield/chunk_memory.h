// voxfield — memory for chunks' voxel arrays, kept between calls for reuse.
//
// Why: a whole field is computed into freshly allocated chunks, read out and freed, and the next
// call does the same. glibc's malloc may hand chunk-sized arrays (32³ floats are 128 KiB, its
// initial mmap threshold) straight to and from the kernel, and trims its heap, and the kernel
// faults and zeroes every 4 KiB page again on first touch. On this project's virtual machine that
// was about half of a Python `distance_transform_edt` of a 256³ volume on one thread (418–475 ms;
// 182–252 ms when glibc was told to keep freed memory: docs/benchmarks.md). So every Grid's voxel
// arrays come from here: a freed array goes onto a list of its size and the next request of that
// size takes it back, warm and resident, up to a limit of cached bytes; beyond the limit arrays go
// back to the system at once.
//
// The limit is process-wide: what set_chunk_cache_limit() set, else the environment variable
// VOXFIELD_CHUNK_CACHE (bytes, or "512M" style: limits.h's parse_byte_size; "0" disables the
// cache; a value that cannot be read makes every chunk allocation throw InvalidArgument naming it,
// until the program sets a limit), else a sixteenth of physical memory capped at 1 GiB. Cached
// bytes are not charged to the memory limit of limits.h, which bounds what one call may allocate.
// Only memory that held voxels before is ever kept: a process that never frees a grid caches
// nothing. trim_chunk_cache() hands all of it back (e.g. after a burst of work). Every function
// here is thread-safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <type_traits>

namespace voxfield {

struct ChunkMemoryStats {
  std::uint64_t cached_bytes = 0;  // freed arrays held for reuse now
  std::uint64_t limit_bytes = 0;   // the limit in force
  std::uint64_t reused = 0;        // requests served from the cache since the process started
  std::uint64_t allocated = 0;     // requests that went to the system
};

// The limit in force (see above).
std::uint64_t chunk_cache_limit();
// Sets the limit (0 disables caching) and hands back what exceeds it. Overrides the environment.
void set_chunk_cache_limit(std::uint64_t bytes);
// Hands every cached array back to the system; the limit stays.
void trim_chunk_cache();
ChunkMemoryStats chunk_memory_stats();

namespace detail {

// Uninitialised storage of `bytes` bytes, 64-byte aligned. Throws std::bad_alloc.
void* allocate_chunk_bytes(std::size_t bytes);
// Returns storage from allocate_chunk_bytes(bytes), of the same `bytes`.
void free_chunk_bytes(void* p, std::size_t bytes) noexcept;

struct ChunkFree {
  std::size_t bytes = 0;
  void operator()(void* p) const noexcept {
    if (p != nullptr) free_chunk_bytes(p, bytes);
  }
};

}  // namespace detail

// One chunk's voxel array: owned storage from the cache above, returned to it when released.
template <class T>
using ChunkArray = std::unique_ptr<T[], detail::ChunkFree>;

// n voxels of T, uninitialised (voxel types are trivially copyable: bytes, integers, floats and
// small structs of them).
template <class T>
ChunkArray<T> make_chunk_array(std::size_t n) {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>,
                "chunk voxels are plain values");
  const std::size_t bytes = n * sizeof(T);
  return ChunkArray<T>(static_cast<T*>(detail::allocate_chunk_bytes(bytes)),
                       detail::ChunkFree{bytes});
}

// The same storage seen as another voxel type of the same size (the exact transform computes in
// unsigned integers in place and hands the chunks out as the field's storage type).
template <class To, class From>
ChunkArray<To> retype_chunk_array(ChunkArray<From>&& a) {
  static_assert(sizeof(To) == sizeof(From) && alignof(To) <= 64);
  static_assert(std::is_trivially_copyable_v<To> && std::is_trivially_destructible_v<To>);
  const detail::ChunkFree free = a.get_deleter();
  return ChunkArray<To>(reinterpret_cast<To*>(a.release()), free);
}

}  // namespace voxfield
