// voxfield — the cache of chunk voxel arrays (voxfield/chunk_memory.h says why it exists).
//
// One mutex guards lists of freed arrays keyed by their size in bytes. A grid holds a few sizes
// only (chunk volume times the voxel's size), and the lists are touched once per chunk allocated
// or freed — hundreds to tens of thousands per whole-field call, against the milliseconds each
// chunk's work takes — so one lock does not contend. The cache object is never destroyed: grids
// in static storage may free their chunks after this file's statics would have been.
#include "voxfield/chunk_memory.h"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <new>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/limits.h"

#if defined(__SANITIZE_ADDRESS__)
#define VOXFIELD_POISON_CACHE 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VOXFIELD_POISON_CACHE 1
#endif
#endif
#ifdef VOXFIELD_POISON_CACHE
#include <sanitizer/asan_interface.h>
#endif

namespace voxfield {
namespace {

constexpr std::align_val_t kAlign{64};

struct Cache {
  std::mutex mutex;
  std::unordered_map<std::size_t, std::vector<void*>> free;  // by size in bytes
  std::uint64_t cached = 0, limit = 0, reused = 0, allocated = 0;
  bool limit_known = false;
  std::string limit_error;  // VOXFIELD_CHUNK_CACHE could not be read
};

Cache& cache() {
  static Cache* c = new Cache;  // never destroyed (see above)
  return *c;
}

std::uint64_t default_limit() {
  const std::uint64_t physical = physical_memory_bytes();
  return physical != 0 ? std::min<std::uint64_t>(physical / 16, std::uint64_t{1} << 30)
                       : std::uint64_t{256} << 20;
}

// Reads the environment once, under the lock. Never throws: a value that cannot be read disables
// the cache and makes every allocation throw, naming it, until set_chunk_cache_limit() is called.
void resolve_limit(Cache& c) noexcept {
  if (c.limit_known) return;
  c.limit_known = true;
  const char* env = std::getenv("VOXFIELD_CHUNK_CACHE");
  if (env == nullptr || *env == '\0') {
    c.limit = default_limit();
    return;
  }
  c.limit = 0;
  try {
    c.limit = parse_byte_size(env, "VOXFIELD_CHUNK_CACHE", ZeroSize::kAllowed);  // 0: off
  } catch (const std::exception& e) {
    try {
      c.limit_error = e.what();
    } catch (...) {
    }
  }
}

void poison(void* p, std::size_t bytes) {
#ifdef VOXFIELD_POISON_CACHE
  ASAN_POISON_MEMORY_REGION(p, bytes);
#else
  static_cast<void>(p);
  static_cast<void>(bytes);
#endif
}

void unpoison(void* p, std::size_t bytes) {
#ifdef VOXFIELD_POISON_CACHE
  ASAN_UNPOISON_MEMORY_REGION(p, bytes);
#else
  static_cast<void>(p);
  static_cast<void>(bytes);
#endif
}

void release(void* p, std::size_t bytes) {
  unpoison(p, bytes);
  ::operator delete(p, kAlign);
}

// Takes arrays off the lists, largest sizes first, until at most `keep` bytes stay cached; the
// caller frees what is returned after dropping the lock.
std::vector<std::pair<void*, std::size_t>> shrink_to(Cache& c, std::uint64_t keep) {
  std::vector<std::pair<void*, std::size_t>> out;
  if (c.cached <= keep) return out;
  std::vector<std::size_t> sizes;
  for (const auto& [bytes, list] : c.free) sizes.push_back(bytes);
  std::sort(sizes.rbegin(), sizes.rend());
  for (const std::size_t bytes : sizes) {
    std::vector<void*>& list = c.free[bytes];
    while (!list.empty() && c.cached > keep) {
      out.emplace_back(list.back(), bytes);
      list.pop_back();
      c.cached -= bytes;
    }
    if (list.empty()) c.free.erase(bytes);
    if (c.cached <= keep) break;
  }
  return out;
}

}  // namespace

namespace detail {

void* allocate_chunk_bytes(std::size_t bytes) {
  Cache& c = cache();
  void* p = nullptr;
  {
    std::lock_guard lock(c.mutex);
    resolve_limit(c);
    if (!c.limit_error.empty()) throw InvalidArgument(c.limit_error);
    if (auto it = c.free.find(bytes); it != c.free.end() && !it->second.empty()) {
      p = it->second.back();
      it->second.pop_back();
      c.cached -= bytes;
      ++c.reused;
    } else {
      ++c.allocated;
    }
  }
  if (p != nullptr) {
    unpoison(p, bytes);
  } else {
    p = ::operator new(bytes, kAlign);
  }
#ifdef VOXFIELD_ENABLE_ASSERTS
  // Builds with the invariant checks hand out a pattern, fresh or reused alike, so that code
  // reading voxels it never wrote sees the same wrong value every run instead of a lucky zero.
  std::memset(p, 0xA5, bytes);
#endif
  return p;
}

void free_chunk_bytes(void* p, std::size_t bytes) noexcept {
  Cache& c = cache();
  {
    std::lock_guard lock(c.mutex);
    resolve_limit(c);
    if (c.cached + bytes <= c.limit) {
      try {
        c.free[bytes].push_back(p);
        c.cached += bytes;
        poison(p, bytes);
        return;
      } catch (...) {  // no room for the list entry: give the array back instead
      }
    }
  }
  release(p, bytes);
}

}  // namespace detail

std::uint64_t chunk_cache_limit() {
  Cache& c = cache();
  std::lock_guard lock(c.mutex);
  resolve_limit(c);
  return c.limit;
}

void set_chunk_cache_limit(std::uint64_t bytes) {
  Cache& c = cache();
  std::vector<std::pair<void*, std::size_t>> excess;
  {
    std::lock_guard lock(c.mutex);
    c.limit_known = true;
    c.limit_error.clear();
    c.limit = bytes;
    excess = shrink_to(c, bytes);
  }
  for (const auto& [p, size] : excess) release(p, size);
}

void trim_chunk_cache() {
  Cache& c = cache();
  std::vector<std::pair<void*, std::size_t>> all;
  {
    std::lock_guard lock(c.mutex);
    all = shrink_to(c, 0);
  }
  for (const auto& [p, size] : all) release(p, size);
}

ChunkMemoryStats chunk_memory_stats() {
  Cache& c = cache();
  std::lock_guard lock(c.mutex);
  resolve_limit(c);
  return {c.cached, c.limit, c.reused, c.allocated};
}

}  // namespace voxfield
