// voxfield — whole-file reads and all-or-nothing writes (write temporary, fsync, rename, fsync
// directory). The temporaries' names, registry and stale sweep are in file_temporaries.cpp.
#include "voxfield/file.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>
#include <utility>

#include "file_temporaries.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {
namespace {

namespace fs = std::filesystem;

std::string errno_text(int err) {
  return std::strerror(err);
}
std::string errno_text() {
  return errno_text(errno);
}

// Owns a file descriptor and closes it on every path out.
class Fd {
 public:
  explicit Fd(int fd) : fd_(fd) {}
  Fd(Fd&& other) noexcept : fd_(other.release()) {}
  ~Fd() {
    if (fd_ >= 0) ::close(fd_);
  }
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

int open_retrying(const char* path, int flags, mode_t mode = 0) {
  int fd;
  do fd = ::open(path, flags, mode);
  while (fd < 0 && errno == EINTR);
  return fd;
}

const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  if (S_ISLNK(mode)) return "a symbolic link";
  return "a special file";
}

// Opens a regular file for reading, refusing anything else without blocking: O_NONBLOCK makes
// open() of a FIFO return at once, fstat says what it is, then reads block as usual.
Fd open_regular(const fs::path& path, struct stat& st) {
  Fd fd(open_retrying(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC));
  if (fd.get() < 0) throw IoError(path.string() + ": cannot open: " + errno_text());
  if (::fstat(fd.get(), &st) != 0) throw IoError(path.string() + ": cannot stat: " + errno_text());
  if (!S_ISREG(st.st_mode)) {
    throw IoError(path.string() + ": is " + kind_of(st.st_mode) + ", not a regular file");
  }
  const int flags = ::fcntl(fd.get(), F_GETFL);
  if (flags < 0 || ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK) != 0) {
    throw IoError(path.string() + ": cannot clear O_NONBLOCK: " + errno_text());
  }
  return fd;
}

// Reads up to `n` bytes (fewer when the file ends first).
std::vector<std::uint8_t> read_up_to(const Fd& fd, const fs::path& path, std::size_t n) {
  std::vector<std::uint8_t> bytes(n);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t got = ::read(fd.get(), bytes.data() + done, bytes.size() - done);
    if (got < 0) {
      if (errno == EINTR) continue;
      throw IoError(path.string() + ": read failed: " + errno_text());
    }
    if (got == 0) break;  // the file shrank while we read it
    done += static_cast<std::size_t>(got);
  }
  bytes.resize(done);
  return bytes;
}

// Writes all of `bytes`, retrying on EINTR and waiting when a non-blocking descriptor (a shared
// standard output) is full. Returns 0 or the errno of the failure.
int write_all(int fd, std::span<const std::uint8_t> bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t put = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (put < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) {
        pollfd wait{fd, POLLOUT, 0};
        ::poll(&wait, 1, -1);
        continue;
      }
      return errno;
    }
    done += static_cast<std::size_t>(put);
  }
  return 0;
}

// What writing to an output path means.
struct Output {
  enum class Kind { kStdout, kNew, kReplace, kInPlace } kind = Kind::kNew;
  fs::path target;      // after following symbolic links: the file to create, replace or open
  struct stat st {};    // of an existing target
  bool append = false;  // in place on a regular file reached through /proc/PID/fd (/dev/stdout)
};

fs::path directory_of(const fs::path& p) {
  return p.has_parent_path() ? p.parent_path() : ".";
}

// Whether the symbolic link `link` is one of the kernel's /proc links (/proc/PID/fd/N, reached
// from /dev/stdout or /dev/fd/N): their text is not a usable path ("pipe:[123]") or names a file
// the process already has open, so they are written in place, never resolved and replaced.
bool is_proc_link(const fs::path& link) {
  std::error_code ec;
  const std::string dir = fs::canonical(directory_of(link), ec).string();
  return !ec && (dir == "/proc" || dir.starts_with("/proc/"));
}

// Follows symbolic links from `path` and refuses what cannot be written; the checks of
// check_output_path, shared with stage().
Output inspect_output(const fs::path& path) {
  Output out;
  if (path == "-") {
    out.kind = Output::Kind::kStdout;
    return out;
  }
  const std::string name = path.string();
  if (name.empty()) throw IoError("\"\": an empty path cannot be an output");
  fs::path p = path;
  const auto where = [&] { return p == path ? std::string() : " (via link, " + p.string() + ")"; };
  for (int links = 0;; ++links) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0) {
      if (errno != ENOENT) throw IoError(name + ": cannot stat" + where() + ": " + errno_text());
      const fs::path dir = directory_of(p);
      struct stat dir_st {};
      if (::stat(dir.c_str(), &dir_st) != 0) {
        const int err = errno;
        if (err == ENOENT) throw IoError(name + ": directory " + dir.string() + " does not exist");
        throw IoError(name + ": cannot access directory " + dir.string() + ": " + errno_text(err));
      }
      if (!S_ISDIR(dir_st.st_mode))
        throw IoError(name + ": " + dir.string() + " is not a directory");
      out.kind = Output::Kind::kNew;
      out.target = p;
      return out;
    }
    if (S_ISLNK(st.st_mode)) {
      if (links == 40) throw IoError(name + ": too many levels of symbolic links");
      if (is_proc_link(p)) {
        if (::stat(p.c_str(), &st) != 0) {
          throw IoError(name + ": cannot stat" + where() + ": " + errno_text());
        }
        if (S_ISDIR(st.st_mode) || S_ISSOCK(st.st_mode)) {
          throw IoError(name + ": is " + kind_of(st.st_mode) + where() + ", not a writable file");
        }
        out.kind = Output::Kind::kInPlace;
        out.target = p;
        out.st = st;
        out.append = S_ISREG(st.st_mode);
        return out;
      }
      std::error_code ec;
      const fs::path text = fs::read_symlink(p, ec);
      if (ec) throw IoError(name + ": cannot read link" + where() + ": " + ec.message());
      p = text.is_absolute() ? text : directory_of(p) / text;
      continue;
    }
    out.target = p;
    out.st = st;
    if (S_ISREG(st.st_mode)) {
      // Root may write anything, so the permission bits are checked explicitly: a file someone
      // made read-only is not to be replaced.
      if ((st.st_mode & 0222) == 0) throw IoError(name + ": is read-only" + where());
      if (::faccessat(AT_FDCWD, p.c_str(), W_OK, AT_EACCESS) != 0 && errno == EACCES) {
        throw IoError(name + ": no permission to write it" + where());
      }
      out.kind = Output::Kind::kReplace;
      return out;
    }
    if (S_ISDIR(st.st_mode) || S_ISSOCK(st.st_mode)) {
      throw IoError(name + ": is " + kind_of(st.st_mode) + where() + ", not a writable file");
    }
    out.kind = Output::Kind::kInPlace;  // a device or a FIFO
    return out;
  }
}

struct Staged {
  fs::path path;  // as the caller gave it, for messages
  Output out;
  fs::path temporary;               // empty when written in place or already renamed/removed
  int slot = -1;                    // in the registry of temporaries
  std::vector<std::uint8_t> bytes;  // kept for an in-place write
  bool shared = false;              // filled by other writers: fsynced at commit
};

// Fills a new temporary for `s` and closes it; `s.temporary` is set as soon as the file exists so
// that the caller's cleanup removes it on any failure.
void write_temporary(Staged& s, std::span<const std::uint8_t> bytes) {
  const std::string name = s.path.string();
  const fs::path dir = directory_of(s.out.target);
  detail::sweep_stale_temporaries(dir);
  const fs::path tmp = dir / detail::temporary_name(s.out.target.filename().string());
  s.slot = detail::register_temporary(tmp);
  Fd fd(open_retrying(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666));
  if (fd.get() < 0) {
    const int err = errno;
    detail::unregister_temporary(std::exchange(s.slot, -1));
    throw IoError(name + ": cannot create a temporary file in " + dir.string() + ": " +
                  errno_text(err));
  }
  s.temporary = tmp;
  if (s.out.kind == Output::Kind::kReplace) {
    // Keep the replaced file's owner (root only can give a file away) and permission bits; chown
    // before chmod, since chown clears set-user-ID bits.
    struct stat now {};
    if (::fstat(fd.get(), &now) != 0)
      throw IoError(name + ": cannot stat temporary: " + errno_text());
    if (::geteuid() == 0 && (now.st_uid != s.out.st.st_uid || now.st_gid != s.out.st.st_gid) &&
        ::fchown(fd.get(), s.out.st.st_uid, s.out.st.st_gid) != 0) {
      throw IoError(name + ": cannot keep the file's owner and group: " + errno_text());
    }
    if (::fchmod(fd.get(), s.out.st.st_mode & 07777) != 0) {
      throw IoError(name + ": cannot keep the file's permissions: " + errno_text());
    }
  }
  if (const int err = write_all(fd.get(), bytes))
    throw IoError(name + ": write failed: " + errno_text(err));
  if (::fsync(fd.get()) != 0) throw IoError(name + ": fsync failed: " + errno_text());
  if (::close(fd.release()) != 0) throw IoError(name + ": close failed: " + errno_text());
}

void write_in_place(const Staged& s) {
  const std::string name = s.path.string();
  if (s.out.kind == Output::Kind::kStdout) {
    if (const int err = write_all(STDOUT_FILENO, s.bytes)) {
      throw IoError(name + ": write to standard output failed: " + errno_text(err));
    }
    return;
  }
  // No O_TRUNC: devices and FIFOs have nothing to truncate, and a regular file reached through
  // /proc is standard output redirected by the shell, which is appended to.
  const int flags = O_WRONLY | O_NOCTTY | O_CLOEXEC | (s.out.append ? O_APPEND : 0);
  Fd fd(open_retrying(s.out.target.c_str(), flags));
  if (fd.get() < 0) throw IoError(name + ": cannot open for writing: " + errno_text());
  if (const int err = write_all(fd.get(), s.bytes)) {
    throw IoError(name + ": write failed: " + errno_text(err));
  }
  if ((S_ISREG(s.out.st.st_mode) || S_ISBLK(s.out.st.st_mode)) && ::fsync(fd.get()) != 0) {
    throw IoError(name + ": fsync failed: " + errno_text());
  }
  if (::close(fd.release()) != 0) throw IoError(name + ": close failed: " + errno_text());
}

}  // namespace

std::vector<std::uint8_t> read_file(const std::filesystem::path& path, std::uint64_t max_bytes) {
  struct stat st {};
  const Fd fd = open_regular(path, st);
  const auto size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes) {
    throw IoError(path.string() + ": file of " + format_bytes(size) + " exceeds the limit of " +
                  format_bytes(max_bytes));
  }
  return read_up_to(fd, path, static_cast<std::size_t>(size));
}

std::vector<std::uint8_t> read_file_prefix(const std::filesystem::path& path, std::size_t n) {
  struct stat st {};
  const Fd fd = open_regular(path, st);
  return read_up_to(fd, path, std::min<std::uint64_t>(n, static_cast<std::uint64_t>(st.st_size)));
}

std::uint64_t regular_file_size(const std::filesystem::path& path) {
  struct stat st {};
  const Fd fd = open_regular(path, st);
  return static_cast<std::uint64_t>(st.st_size);
}

FileReader::FileReader(const std::filesystem::path& path) : path_(path) {
  struct stat st {};
  Fd fd = open_regular(path, st);
  size_ = static_cast<std::uint64_t>(st.st_size);
  fd_ = fd.release();
}

FileReader::~FileReader() {
  if (fd_ >= 0) ::close(fd_);
}

void FileReader::read_at(std::uint64_t offset, std::size_t n, std::uint8_t* out) const {
  std::size_t done = 0;
  while (done < n) {
    const ssize_t got = ::pread(fd_, out + done, n - done, static_cast<off_t>(offset + done));
    if (got < 0) {
      if (errno == EINTR) continue;
      throw IoError(path_.string() + ": read of " + std::to_string(n) + " bytes at offset " +
                    std::to_string(offset) + " failed: " + errno_text());
    }
    if (got == 0)
      throw IoError(path_.string() + ": ends at " + std::to_string(offset + done) +
                    " bytes, before the " + std::to_string(n) + " bytes read at offset " +
                    std::to_string(offset) + " (did it shrink while read?)");
    done += static_cast<std::size_t>(got);
  }
}

void check_output_path(const std::filesystem::path& path) {
  (void)inspect_output(path);
}

bool same_file(const std::filesystem::path& a, const std::filesystem::path& b) {
  std::error_code ec;
  const bool same = std::filesystem::equivalent(a, b, ec);
  return !ec && same;
}

std::string lowercase_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool same_target(const std::filesystem::path& a, const std::filesystem::path& b) {
  if (a == "-" || b == "-") return a == b;  // standard output once at most
  if (same_file(a, b)) return true;
  std::error_code ea, eb;
  const auto ca = std::filesystem::weakly_canonical(a, ea),
             cb = std::filesystem::weakly_canonical(b, eb);
  return !ea && !eb && ca == cb;
}

struct FileTransaction::Impl {
  std::vector<Staged> staged;
  std::string failure;  // the error that ended this transaction, if one did

  // Adds a target and lets `fill` write it; any failure ends the transaction (every temporary
  // removed) and is rethrown, and a transaction that failed before refuses new targets.
  template <class Fill>
  void stage(const std::filesystem::path& path, Fill&& fill) {
    if (!failure.empty())
      throw IoError(path.string() + ": not staged, the transaction failed earlier: " + failure);
    try {
      staged.emplace_back();
      Staged& s = staged.back();
      s.path = path;
      s.out = inspect_output(path);
      fill(s);
    } catch (const std::exception& e) {
      failure = e.what();
      discard();
      throw;
    }
  }

  // Removes every temporary; no target is touched. Never throws.
  void discard() noexcept {
    for (Staged& s : staged) {
      if (!s.temporary.empty()) ::unlink(s.temporary.c_str());
      detail::unregister_temporary(std::exchange(s.slot, -1));
    }
    staged.clear();
  }
};

FileTransaction::FileTransaction() : impl_(std::make_unique<Impl>()) {}

FileTransaction::~FileTransaction() {
  impl_->discard();
}

void FileTransaction::stage(const std::filesystem::path& path,
                            std::span<const std::uint8_t> bytes) {
  impl_->stage(path, [&](Staged& s) {
    if (s.out.kind == Output::Kind::kStdout || s.out.kind == Output::Kind::kInPlace) {
      s.bytes.assign(bytes.begin(), bytes.end());
    } else {
      write_temporary(s, bytes);
    }
  });
}

std::filesystem::path FileTransaction::stage_shared(const std::filesystem::path& path,
                                                    std::span<const std::uint8_t> head) {
  std::filesystem::path temporary;
  impl_->stage(path, [&](Staged& s) {
    if (s.out.kind == Output::Kind::kStdout || s.out.kind == Output::Kind::kInPlace)
      throw IoError(path.string() + ": is not a regular file, which several processes could write");
    s.shared = true;
    write_temporary(s, head);
    temporary = s.temporary;
  });
  return temporary;
}

void FileTransaction::stage(const std::filesystem::path& path, std::string_view text) {
  stage(path, std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
}

void FileTransaction::commit() {
  if (!impl_->failure.empty()) {
    throw IoError(impl_->failure + " (so the transaction cannot be committed)");
  }
  std::vector<std::pair<fs::path, fs::path>> directories;  // each with the first target in it
  try {
    // In-place outputs (standard output, devices, FIFOs) first: they are the ones that can fail
    // at this point (a full device, a closed pipe) and cannot be undone, so a failure among them
    // leaves every renamed target untouched. The renames that follow do not fail in practice.
    for (Staged& s : impl_->staged) {
      if (s.temporary.empty()) write_in_place(s);
    }
    for (Staged& s : impl_->staged) {
      if (!s.shared) continue;
      Fd fd(open_retrying(s.temporary.c_str(), O_WRONLY | O_NOFOLLOW | O_CLOEXEC));
      if (fd.get() < 0 || ::fsync(fd.get()) != 0)
        throw IoError(s.path.string() + ": fsync of the written file failed: " + errno_text());
    }
    for (Staged& s : impl_->staged) {
      if (s.temporary.empty()) continue;
      if (::rename(s.temporary.c_str(), s.out.target.c_str()) != 0) {
        throw IoError(s.path.string() + ": cannot replace " + s.out.target.string() + ": " +
                      errno_text());
      }
      s.temporary.clear();
      detail::unregister_temporary(std::exchange(s.slot, -1));
      const fs::path dir = directory_of(s.out.target);
      const auto same_dir = [&](const auto& entry) { return entry.first == dir; };
      if (std::none_of(directories.begin(), directories.end(), same_dir)) {
        directories.emplace_back(dir, s.path);
      }
    }
  } catch (const std::exception& e) {
    impl_->failure = e.what();
    impl_->discard();
    throw;
  }
  impl_->staged.clear();
  // Make the renames themselves durable. Some file systems cannot fsync a directory (EINVAL).
  for (const auto& [dir, path] : directories) {
    Fd dir_fd(open_retrying(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
    if (dir_fd.get() >= 0 && ::fsync(dir_fd.get()) != 0 && errno != EINVAL) {
      throw IoError(path.string() + ": written, but fsync of its directory " + dir.string() +
                    " failed: " + errno_text());
    }
  }
}

void write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes) {
  FileTransaction transaction;
  transaction.stage(path, bytes);
  transaction.commit();
}

}  // namespace voxfield
