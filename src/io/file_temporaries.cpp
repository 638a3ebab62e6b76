// voxfield — the temporaries of FileTransaction: names, the signal-safe registry, stale sweep.
#include "file_temporaries.h"

#include <dirent.h>
#include <fcntl.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <system_error>

#include "voxfield/file.h"

namespace voxfield::detail {
namespace {

constexpr std::string_view kTag = ".vftmp.";

// The registry. A signal handler may only touch lock-free atomics and call async-signal-safe
// functions, so it is a fixed array of fixed-size path buffers, each guarded by a state word:
// the owner claims a free slot, fills the path, then publishes it; the handler takes a live slot
// (so that its owner cannot reuse the buffer under it) and unlink()s the path.
enum SlotState : int { kFree = 0, kFilling = 1, kLive = 2, kTakenByHandler = 3 };
static_assert(std::atomic<int>::is_always_lock_free);

struct Slot {
  std::atomic<int> state{kFree};
  pid_t owner = 0;  // a forked child inherits the registry; only the owner removes the file
  char path[PATH_MAX];
};

constexpr int kSlots = 64;
Slot g_slots[kSlots];

void remove_live_temporaries() {
  const pid_t self = ::getpid();
  for (Slot& slot : g_slots) {
    int expected = kLive;
    if (slot.state.compare_exchange_strong(expected, kTakenByHandler, std::memory_order_acquire) &&
        slot.owner == self) {
      ::unlink(slot.path);
    }
  }
}

extern "C" void cleanup_and_reraise(int sig) {
  const int saved_errno = errno;
  remove_live_temporaries();
  // Die of the same signal, so that the parent's wait status says what happened.
  struct sigaction dfl {};
  dfl.sa_handler = SIG_DFL;
  sigemptyset(&dfl.sa_mask);
  ::sigaction(sig, &dfl, nullptr);
  sigset_t unblock;
  sigemptyset(&unblock);
  sigaddset(&unblock, sig);
  ::sigprocmask(SIG_UNBLOCK, &unblock, nullptr);
  ::raise(sig);
  errno = saved_errno;
}

// This host, as 8 lowercase hex digits of the FNV-1a hash of its name: a temporary's writer is
// judged dead by its PID only on its own host (a directory may be shared between hosts, as an MPI
// job's ranks share one on a cluster's file system).
const std::string& host_tag() {
  static const std::string tag = [] {
    char name[256] = {};
    if (::gethostname(name, sizeof name - 1) != 0) name[0] = '\0';
    std::uint32_t h = 2166136261u;
    for (const char* c = name; *c; ++c) {
      h ^= static_cast<unsigned char>(*c);
      h *= 16777619u;
    }
    char hex[9];
    std::snprintf(hex, sizeof hex, "%08x", h);
    return std::string(hex);
  }();
  return tag;
}

bool is_host_tag(std::string_view s) {
  if (s.size() != 8) return false;
  for (const char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

bool all_digits_no_leading_zero(std::string_view s) {
  if (s.empty() || (s.size() > 1 && s[0] == '0')) return false;
  for (const char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

}  // namespace

std::string temporary_name(std::string_view target_name) {
  static std::atomic<std::uint64_t> counter{0};
  const std::string suffix = std::string(kTag) + host_tag() + "." + std::to_string(::getpid()) +
                             "." + std::to_string(counter.fetch_add(1, std::memory_order_relaxed));
  // "." + stem + suffix must fit in NAME_MAX bytes; the suffix is at most 7 + 9 + 10 + 1 + 20
  // bytes.
  const std::size_t room = NAME_MAX - 1 - suffix.size();
  std::size_t keep = target_name.size();
  if (keep > room) {
    keep = room;
    // Do not cut a UTF-8 sequence: back up over continuation bytes (10xxxxxx).
    while (keep > 0 && (static_cast<unsigned char>(target_name[keep]) & 0xC0) == 0x80) --keep;
  }
  std::string stem(target_name.substr(0, keep));
  if (stem.empty()) stem = "_";
  return "." + stem + suffix;
}

bool parse_temporary_name(std::string_view name, pid_t& pid, bool& this_host) {
  if (name.size() < 2 || name[0] != '.') return false;
  const std::size_t n_dot = name.rfind('.');
  if (!all_digits_no_leading_zero(name.substr(n_dot + 1))) return false;
  std::string_view rest = name.substr(0, n_dot);  // ".<anything>.vftmp.[<host>.]<pid>"
  const std::size_t pid_dot = rest.rfind('.');
  const std::string_view pid_text = rest.substr(pid_dot + 1);
  if (pid_text.size() > 9 || !all_digits_no_leading_zero(pid_text)) return false;
  rest = rest.substr(0, pid_dot + 1);  // ".<anything>.vftmp.[<host>.]"
  this_host = true;  // names without a host are this host's (written before hosts were named)
  if (!rest.ends_with(kTag)) {
    const std::size_t host_dot = rest.substr(0, rest.size() - 1).rfind('.');
    if (host_dot == std::string_view::npos) return false;
    const std::string_view host = rest.substr(host_dot + 1, rest.size() - host_dot - 2);
    if (!is_host_tag(host)) return false;
    this_host = host == host_tag();
    rest = rest.substr(0, host_dot + 1);
  }
  if (rest.size() <= 1 + kTag.size() || !rest.ends_with(kTag)) return false;
  pid = static_cast<pid_t>(std::stol(std::string(pid_text)));
  return pid > 0;
}

void sweep_stale_temporaries(const std::filesystem::path& dir) {
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr) return;
  const int dir_fd = ::dirfd(d);
  const pid_t self = ::getpid();
  while (const dirent* entry = ::readdir(d)) {
    pid_t pid = 0;
    bool this_host = true;
    if (!parse_temporary_name(entry->d_name, pid, this_host) || !this_host || pid == self) continue;
    if (::kill(pid, 0) == 0 || errno != ESRCH) continue;  // alive (EPERM: alive, someone else's)
    struct stat st {};
    if (::fstatat(dir_fd, entry->d_name, &st, AT_SYMLINK_NOFOLLOW) != 0 || !S_ISREG(st.st_mode)) {
      continue;
    }
    ::unlinkat(dir_fd, entry->d_name, 0);
  }
  ::closedir(d);
}

int register_temporary(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  if (ec || absolute.native().size() >= PATH_MAX) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (!g_slots[i].state.compare_exchange_strong(expected, kFilling, std::memory_order_acquire)) {
      continue;
    }
    std::memcpy(g_slots[i].path, absolute.c_str(), absolute.native().size() + 1);
    g_slots[i].owner = ::getpid();
    g_slots[i].state.store(kLive, std::memory_order_release);
    return i;
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot < 0) return;
  // Fails only when a signal handler has taken the slot: the process is about to die, and the
  // slot must not be reused under the handler.
  int expected = kLive;
  g_slots[slot].state.compare_exchange_strong(expected, kFree, std::memory_order_acq_rel);
}

}  // namespace voxfield::detail

namespace voxfield {

void install_signal_cleanup() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction action {};
    action.sa_handler = detail::cleanup_and_reraise;
    sigemptyset(&action.sa_mask);
    const int signals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
    // While one of them is being handled, the others wait: the handler runs once.
    for (const int sig : signals) sigaddset(&action.sa_mask, sig);
    for (const int sig : signals) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) != 0) continue;
      const bool is_default = (old.sa_flags & SA_SIGINFO) == 0 && old.sa_handler == SIG_DFL;
      if (is_default) ::sigaction(sig, &action, nullptr);
    }
  });
}

}  // namespace voxfield
