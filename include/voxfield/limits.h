// voxfield — limits: the memory budget that readers and dense buffers respect.
//
// Every reader estimates what a file will cost once decoded (chunks it touches, bytes it
// decompresses to) before allocating it, and every operation that needs one dense buffer over a
// box checks its size first; past the limit they throw ResourceLimitError naming the file or the
// operation, what it needs and the limit, having allocated nothing for it.
//
// The limit is per call where the call takes options (VoxImportOptions, NpyReadOptions, ...: 0
// means the process default) and process-wide otherwise. The process default is, in order: what
// set_default_memory_limit() set, the environment variable VOXFIELD_MEMORY_LIMIT (bytes, or with
// a binary suffix K, M, G, T: "8G"), half of the machine's physical memory. The coordinate range
// is in box.h (kCoordRange). docs/limits.md lists every limit and what each refusal says.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "voxfield/box.h"

namespace voxfield {

// Physical memory of this machine in bytes (sysconf), or 0 when unknown.
std::uint64_t physical_memory_bytes();

// The process-wide memory limit in bytes (see above). Thread-safe.
std::uint64_t default_memory_limit();
// Sets the process-wide limit; 0 restores the default from the environment or physical memory.
void set_default_memory_limit(std::uint64_t bytes);
// `limit` itself, or the process default when it is 0.
inline std::uint64_t effective_memory_limit(std::uint64_t limit) {
  return limit != 0 ? limit : default_memory_limit();
}

// Whether a size of 0 (in any unit) is a value — "off", for a cache — or refused.
enum class ZeroSize { kRefused, kAllowed };
// "123", "64K", "512M", "8G", "1T", "8 GiB" (binary units, case-insensitive, optional trailing "B"
// or "iB", spaces around the number) -> bytes. Throws InvalidArgument naming `what` for anything
// else, and for 0 unless `zero` allows it.
std::uint64_t parse_byte_size(std::string_view text, std::string_view what = "memory limit",
                              ZeroSize zero = ZeroSize::kRefused);
// "1.5 GiB", "12.0 MiB", "980 B".
std::string format_bytes(std::uint64_t bytes);

// Throws ResourceLimitError "<who>: <what> needs <need>, more than the memory limit of <limit>
// (...how to raise it)" when need_bytes > limit_bytes (0: the process default).
void require_memory(std::uint64_t need_bytes, std::uint64_t limit_bytes, const std::string& who,
                    const std::string& what);

// What is left of a limit (0: the process default) once `used` bytes are held: at least 1, so
// that the result is never read as "the default". Readers hand it on for the decoded data while
// they hold the file's bytes.
inline std::uint64_t remaining_memory(std::uint64_t limit, std::uint64_t used) {
  const std::uint64_t l = effective_memory_limit(limit);
  return used < l ? l - used : 1;
}

// Saturating arithmetic for sizes that come from files: never wraps, caps at UINT64_MAX.
constexpr std::uint64_t mul_sat(std::uint64_t a, std::uint64_t b) {
  return (a != 0 && b > UINT64_MAX / a) ? UINT64_MAX : a * b;
}
constexpr std::uint64_t add_sat(std::uint64_t a, std::uint64_t b) {
  return b > UINT64_MAX - a ? UINT64_MAX : a + b;
}
// Bytes of a dense array over `box` at `bytes_per_voxel` (saturating).
constexpr std::uint64_t dense_bytes(const Box3i& box, std::uint64_t bytes_per_voxel) {
  return mul_sat(static_cast<std::uint64_t>(box.volume()), bytes_per_voxel);
}

}  // namespace voxfield
