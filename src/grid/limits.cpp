// voxfield — the memory limit (voxfield/limits.h).
#include "voxfield/limits.h"

#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cstdio>
#include <cstdlib>

#include "voxfield/error.h"

namespace voxfield {
namespace {

std::atomic<std::uint64_t> g_limit{0};  // 0: not set by the program

std::uint64_t environment_or_physical_default() {
  if (const char* env = std::getenv("VOXFIELD_MEMORY_LIMIT"); env != nullptr && *env != '\0') {
    return parse_byte_size(env, "VOXFIELD_MEMORY_LIMIT");
  }
  const std::uint64_t physical = physical_memory_bytes();
  // Half of the machine leaves room for the rest of the process and the system; unknown
  // machines get 4 GiB.
  return physical != 0 ? physical / 2 : std::uint64_t{4} << 30;
}

}  // namespace

std::uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES);
  const long page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return 0;
  return mul_sat(static_cast<std::uint64_t>(pages), static_cast<std::uint64_t>(page));
}

std::uint64_t default_memory_limit() {
  const std::uint64_t set = g_limit.load(std::memory_order_relaxed);
  return set != 0 ? set : environment_or_physical_default();
}

void set_default_memory_limit(std::uint64_t bytes) {
  g_limit.store(bytes, std::memory_order_relaxed);
}

std::uint64_t parse_byte_size(std::string_view text, std::string_view what, ZeroSize zero) {
  auto bad = [&](const char* why) -> std::uint64_t {
    throw InvalidArgument(std::string(what) + ": \"" + std::string(text) + "\" " + why +
                          " (expected bytes or a size such as 512M, 8G)");
  };
  // Spaces around the number and before the unit are allowed ("8 GiB", as format_bytes writes).
  while (!text.empty() && text.front() == ' ') text.remove_prefix(1);
  while (!text.empty() && text.back() == ' ') text.remove_suffix(1);
  std::size_t i = 0;
  std::uint64_t v = 0;
  while (i < text.size() && std::isdigit(static_cast<unsigned char>(text[i]))) {
    const std::uint64_t d = static_cast<std::uint64_t>(text[i] - '0');
    if (v > (UINT64_MAX - d) / 10) return bad("is too large");
    v = v * 10 + d;
    ++i;
  }
  if (i == 0) return bad("is not a size");
  while (i < text.size() && text[i] == ' ') ++i;
  std::string unit;
  for (; i < text.size(); ++i)
    unit += static_cast<char>(std::toupper(static_cast<unsigned char>(text[i])));
  int shift = 0;
  if (unit.empty() || unit == "B") {
    shift = 0;
  } else {
    const std::string_view u(unit);
    const std::string_view rest = u.substr(1);
    if (!(rest.empty() || rest == "B" || rest == "IB")) return bad("has an unknown unit");
    switch (u[0]) {
      case 'K':
        shift = 10;
        break;
      case 'M':
        shift = 20;
        break;
      case 'G':
        shift = 30;
        break;
      case 'T':
        shift = 40;
        break;
      default:
        return bad("has an unknown unit");
    }
  }
  if (v > (UINT64_MAX >> shift)) return bad("is too large");
  v <<= shift;
  if (v == 0 && zero == ZeroSize::kRefused) return bad("must be more than 0 bytes");
  return v;
}

std::string format_bytes(std::uint64_t bytes) {
  static const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return std::to_string(bytes) + " B";
  double v = static_cast<double>(bytes) / 1024.0;
  int u = 0;
  while (v >= 1024.0 && u < 5) {
    v /= 1024.0;
    ++u;
  }
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %s", v, units[u]);
  return buf;
}

void require_memory(std::uint64_t need_bytes, std::uint64_t limit_bytes, const std::string& who,
                    const std::string& what) {
  const std::uint64_t limit = effective_memory_limit(limit_bytes);
  if (need_bytes <= limit) return;
  throw ResourceLimitError(
      who + ": " + what + " needs " +
      (need_bytes == UINT64_MAX ? std::string("more than 16 EiB") : format_bytes(need_bytes)) +
      ", more than the memory limit of " + format_bytes(limit) +
      " (raise it with --memory-limit or VOXFIELD_MEMORY_LIMIT)");
}

}  // namespace voxfield
