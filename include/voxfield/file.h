// voxfield — whole-file reads and all-or-nothing writes, used by every reader and writer.
//
// Every function throws voxfield::IoError on failure, with a message that starts with the path it
// was given and says the cause. Nothing here exits, prints or installs signal handlers by itself.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string_view>
#include <vector>

namespace voxfield {

// Reads a whole regular file. Throws IoError naming the file when it cannot be opened or read,
// when it is not a regular file (a directory, FIFO, device or socket is refused without blocking:
// it is opened with O_NONBLOCK and checked with fstat before anything is read), or when it is
// larger than `max_bytes` (the message gives both sizes in readable units, e.g. "file of 256.0 MiB
// exceeds the limit of 64.0 MiB").
std::vector<std::uint8_t> read_file(const std::filesystem::path& path,
                                    std::uint64_t max_bytes = std::uint64_t{1} << 36);

// The first min(n, size) bytes of a regular file (same refusals as read_file), e.g. to check a
// magic number before reading a large file.
std::vector<std::uint8_t> read_file_prefix(const std::filesystem::path& path, std::size_t n);

// Size in bytes of a regular file (same refusals as read_file).
std::uint64_t regular_file_size(const std::filesystem::path& path);

// A regular file open for reading pieces of it (same refusals as read_file), so that a large
// array can be read a part at a time. Not for concurrent use from several threads.
class FileReader {
 public:
  explicit FileReader(const std::filesystem::path& path);
  ~FileReader();
  FileReader(const FileReader&) = delete;
  FileReader& operator=(const FileReader&) = delete;

  std::uint64_t size() const { return size_; }
  // Exactly `n` bytes at `offset` into `out`. Throws IoError naming the file when the file ends
  // first (it shrank after opening) or a read fails.
  void read_at(std::uint64_t offset, std::size_t n, std::uint8_t* out) const;

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

// Checks, without writing or creating anything, that `path` can be written as an output of
// FileTransaction / write_file_atomic: "-" (standard output) is fine; otherwise (after following
// symbolic links) the parent directory must exist and be a directory, the path must not be a
// directory or a socket, and an existing regular file must not be read-only (no write permission
// bit set, which is refused for root too) nor unwritable by this process. Throws IoError naming
// the path and the cause.
void check_output_path(const std::filesystem::path& path);

// Whether two paths name the same existing file (std::filesystem::equivalent, following symbolic
// links); false when either does not exist or cannot be examined.
bool same_file(const std::filesystem::path& a, const std::filesystem::path& b);
// Whether two paths name one target to write: the same existing file, or the same path once made
// absolute (a file not written yet); "-" (standard output) is only itself.
bool same_target(const std::filesystem::path& a, const std::filesystem::path& b);

// A path's extension in lower case (".NPY" reads as ".npy"): how every format is told by name.
std::string lowercase_extension(const std::filesystem::path& path);

// A set of output files written all or nothing.
//
// stage() checks the target as check_output_path does, then writes the bytes to a temporary file
// `.NAME.vftmp.HOST.PID.N` beside the target (in the directory of the file a symbolic link points
// to), fsynced and closed. For "-" (standard output), a character or block device, a FIFO, or a
// file reached through /proc/PID/fd (e.g. /dev/stdout), it instead keeps a copy of the bytes to
// write in place at commit (appending when that is a regular file). Before creating a temporary it
// removes stale temporaries of dead processes from that directory (see below).
//
// commit() then, in staging order, renames each temporary onto its target or writes the kept
// bytes in place (opening a FIFO waits for a reader), and fsyncs the directories. Each rename is
// atomic, the set is not: if commit() fails part-way, the targets before the failing one are
// written, the failing one and the rest are not, and every remaining temporary is removed.
//
// If anything fails before commit() — a stage() throws, or the transaction is destroyed
// uncommitted — every temporary is removed and no target is touched; once a stage() has failed,
// later stage() and commit() calls throw. After a successful commit() the transaction is empty
// and may be used again.
//
// Targets: a symbolic link is written through (the file it points to is replaced atomically and
// the link stays; a dangling link creates its target); an existing regular file keeps its
// permission bits (and, when running as root, its owner and group); a read-only existing file is
// refused (IoError, file untouched); a new file gets 0666 & ~umask. Replacing a file gives it a
// new inode: other hard links to the old file keep the old content.
//
// Temporaries: N is a process-wide counter; NAME is shortened when the whole name would exceed
// 255 bytes. Live temporaries are listed in a fixed process-wide registry that the handlers of
// install_signal_cleanup() remove; should more than 64 be live at once, the others are not
// listed (they are still removed on every path out of this class except a signal or kill -9, and
// swept by the next write into their directory after the process has died). Stale temporaries:
// entries named exactly `.<anything>.vftmp.<host>.<pid>.<n>` (or, from older versions,
// `.<anything>.vftmp.<pid>.<n>`) that are regular files, written on this host (HOST: 8 hex digits
// of a hash of the host name; another host's PIDs mean nothing here, so its temporaries in a
// shared directory are never touched), and whose pid is not a live process (kill(pid, 0) fails with
// ESRCH) are unlinked; nothing else is touched. A process in another PID namespace sharing the
// directory would look dead.
class FileTransaction {
 public:
  FileTransaction();
  ~FileTransaction();
  FileTransaction(const FileTransaction&) = delete;
  FileTransaction& operator=(const FileTransaction&) = delete;

  void stage(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);
  void stage(const std::filesystem::path& path, std::string_view text);
  // Stages a target that other writers fill: the temporary is created holding `head` and its path
  // returned; the caller has it written (e.g. by the processes of an MPI job) before commit(),
  // which fsyncs it before the rename. Regular-file targets only: standard output, devices and
  // FIFOs cannot be written by several processes (IoError).
  std::filesystem::path stage_shared(const std::filesystem::path& path,
                                     std::span<const std::uint8_t> head);
  void commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One file: a FileTransaction of one stage() and commit(). A crash or kill at any moment leaves
// either the old file or the new one, never a mix.
void write_file_atomic(const std::filesystem::path& path, std::span<const std::uint8_t> bytes);

// Installs handlers for SIGINT, SIGTERM, SIGHUP and SIGQUIT that remove every temporary that
// voxfield is writing in this process, then re-raise the signal with its default action (so the
// exit status shows the signal). A signal whose disposition is not the default (ignored, e.g.
// under nohup, or already handled by the caller) is left alone. The library never installs them
// by itself; front ends (CLI, demo) call this once at start. Idempotent and thread-safe.
void install_signal_cleanup();

}  // namespace voxfield
