#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <thread>

#include "voxfield/error.h"
#include "voxfield/file.h"

using namespace voxfield;
namespace fs = std::filesystem;

namespace {

// A fresh directory for one test, removed at the end.
class ScratchDir {
 public:
  ScratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / ("voxfield_file_" + std::string(info->test_suite_name()) +
                                         "_" + info->name() + "_" + std::to_string(::getpid()));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }

 private:
  fs::path path_;
};

std::vector<std::uint8_t> bytes_of(std::string_view text) {
  return {text.begin(), text.end()};
}

void put(const fs::path& p, std::string_view text) {
  std::ofstream(p, std::ios::binary) << text;
}

int count_temporaries(const fs::path& dir) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    n += e.path().filename().string().find(".vftmp.") != std::string::npos;
  }
  return n;
}

fs::perms permissions(const fs::path& p) {
  return fs::status(p).permissions();
}

// The message of the IoError that `f` throws ("" if none).
template <class F>
std::string io_error_of(F&& f) {
  try {
    f();
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

pid_t dead_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

}  // namespace

TEST(File, AtomicWriteReplacesAndLeavesNoTemporaries) {
  const fs::path dir =
      fs::temp_directory_path() / ("voxfield_file_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / "x.bin";
  const std::vector<std::uint8_t> a{1, 2, 3}, b(100000, 7);
  write_file_atomic(p, a);
  EXPECT_EQ(read_file(p), a);
  write_file_atomic(p, b);
  EXPECT_EQ(read_file(p), b);
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) entries += e.is_regular_file();
  EXPECT_EQ(entries, 1);
  fs::remove_all(dir);
}

TEST(File, ErrorsNameTheFile) {
  try {
    read_file("/nonexistent/voxfield/file.vox");
    FAIL();
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/voxfield/file.vox"), std::string::npos);
  }
  EXPECT_THROW(write_file_atomic("/nonexistent/voxfield/out.vox", std::vector<std::uint8_t>{1}),
               IoError);
  EXPECT_THROW(read_file(fs::temp_directory_path()), IoError);  // a directory
}

TEST(File, WritesThroughSymlinks) {
  ScratchDir dir;
  put(dir / "target.bin", "old");
  fs::create_symlink("target.bin", dir / "link.bin");  // relative, as users make them
  write_file_atomic(dir / "link.bin", bytes_of("new"));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "link.bin")));
  EXPECT_EQ(fs::read_symlink(dir / "link.bin"), "target.bin");
  EXPECT_EQ(read_file(dir / "target.bin"), bytes_of("new"));

  // A dangling link creates its target, in the target's directory.
  fs::create_directory(dir / "sub");
  fs::create_symlink(dir / "sub" / "made.bin", dir / "dangling.bin");
  write_file_atomic(dir / "dangling.bin", bytes_of("made"));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir / "dangling.bin")));
  EXPECT_EQ(read_file(dir / "sub" / "made.bin"), bytes_of("made"));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
  EXPECT_EQ(count_temporaries(dir / "sub"), 0);
}

TEST(File, WritesDevNullInPlace) {
  if (::access("/dev/null", W_OK) != 0) GTEST_SKIP() << "/dev/null is not writable";
  write_file_atomic("/dev/null", bytes_of("discarded"));
  EXPECT_TRUE(fs::is_character_file(fs::symlink_status("/dev/null")));
  EXPECT_EQ(count_temporaries("/dev"), 0);
}

TEST(File, WritesFifoInPlace) {
  ScratchDir dir;
  const fs::path fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // Held open read-write so that neither side's open() blocks, whatever the code under test does;
  // closing it gives the reader its end of file.
  const int keep = ::open(fifo.c_str(), O_RDWR | O_CLOEXEC);
  ASSERT_GE(keep, 0);
  std::vector<std::uint8_t> received;
  std::thread reader([&] {
    const int fd = ::open(fifo.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return;
    std::uint8_t buffer[4096];
    for (ssize_t got; (got = ::read(fd, buffer, sizeof buffer)) > 0;) {
      received.insert(received.end(), buffer, buffer + got);
    }
    ::close(fd);
  });
  std::vector<std::uint8_t> sent(200000);  // more than a pipe holds
  for (std::size_t i = 0; i < sent.size(); ++i) sent[i] = static_cast<std::uint8_t>(i * 7);
  EXPECT_NO_THROW(write_file_atomic(fifo, sent));
  ::close(keep);
  reader.join();
  EXPECT_EQ(received, sent);
  EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(File, WritesThroughProcFdLinksInPlace) {
  // What --stats /dev/stdout does when the shell redirected standard output to a file: append to
  // that file (same inode), never replace the link's target.
  ScratchDir dir;
  const fs::path log = dir / "log.txt";
  put(log, "abc");
  const int fd = ::open(log.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  const auto links_before = fs::hard_link_count(log);
  struct stat before {};
  ASSERT_EQ(::stat(log.c_str(), &before), 0);
  write_file_atomic("/dev/fd/" + std::to_string(fd), bytes_of("def"));
  ::close(fd);
  struct stat after {};
  ASSERT_EQ(::stat(log.c_str(), &after), 0);
  EXPECT_EQ(after.st_ino, before.st_ino);
  EXPECT_EQ(fs::hard_link_count(log), links_before);
  EXPECT_EQ(read_file(log), bytes_of("abcdef"));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(File, KeepsModeAndOwnerOfReplacedFile) {
  ScratchDir dir;
  const fs::path p = dir / "secret.bin";
  put(p, "old");
  fs::permissions(p, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::replace);
  const bool root = ::geteuid() == 0;
  if (root) {
    ASSERT_EQ(::chown(p.c_str(), 12345, 23456), 0);
  }
  write_file_atomic(p, bytes_of("new"));
  EXPECT_EQ(read_file(p), bytes_of("new"));
  EXPECT_EQ(permissions(p), fs::perms::owner_read | fs::perms::owner_write);
  if (root) {
    struct stat st {};
    ASSERT_EQ(::stat(p.c_str(), &st), 0);
    EXPECT_EQ(st.st_uid, 12345u);
    EXPECT_EQ(st.st_gid, 23456u);
  }
}

TEST(File, NewFilesGetUmaskedMode) {
  ScratchDir dir;
  const mode_t old_mask = ::umask(027);
  write_file_atomic(dir / "new.bin", bytes_of("x"));
  ::umask(old_mask);
  EXPECT_EQ(static_cast<unsigned>(permissions(dir / "new.bin")), 0640u);
}

TEST(File, RefusesReadOnlyFile) {
  ScratchDir dir;
  const fs::path p = dir / "frozen.bin";
  put(p, "keep me");
  fs::permissions(p, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read,
                  fs::perm_options::replace);
  const std::string message = io_error_of([&] { write_file_atomic(p, bytes_of("overwritten")); });
  EXPECT_TRUE(message.starts_with(p.string())) << message;
  EXPECT_NE(message.find("read-only"), std::string::npos) << message;
  EXPECT_EQ(read_file(p), bytes_of("keep me"));
  EXPECT_EQ(static_cast<unsigned>(permissions(p)), 0444u);
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(File, WritesLongestNames) {
  ScratchDir dir;
  for (const std::size_t length : {251u, 255u}) {
    const fs::path p = dir / std::string(length, 'n');
    write_file_atomic(p, bytes_of("long"));
    EXPECT_EQ(read_file(p), bytes_of("long")) << length;
  }
  // Multi-byte characters are not cut in the temporary's name (125 two-byte 'é' + ".bin").
  std::string accented;
  for (int i = 0; i < 125; ++i) accented += "\xC3\xA9";
  write_file_atomic(dir / (accented + ".bin"), bytes_of("é"));
  EXPECT_EQ(read_file(dir / (accented + ".bin")), bytes_of("é"));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(File, SweepsStaleTemporariesOfDeadProcessesOnly) {
  ScratchDir dir;
  const std::string dead = std::to_string(dead_pid());
  const std::string alive = std::to_string(::getpid());
  const std::vector<std::string> kept = {
      ".x.bin.vftmp." + alive + ".0",  // a live process (this one) may still be writing it
      ".x.bin.vftmp.notapid.0",        // not our pattern
      ".x.bin.tmp." + dead + ".0",     // the old pattern: not ours to judge
      ".x.bin.vftmp." + dead + ".0.bak", "unrelated.txt", "x.bin.vftmp." + dead + ".0"};
  for (const auto& name : kept) put(dir / name, "k");
  put(dir / (".x.bin.vftmp." + dead + ".0"), "stale");
  put(dir / (".other.npy.vftmp." + dead + ".17"), "stale");
  fs::create_directory(dir / (".d.vftmp." + dead + ".1"));  // a directory: never touched

  write_file_atomic(dir / "y.bin", bytes_of("y"));

  EXPECT_FALSE(fs::exists(dir / (".x.bin.vftmp." + dead + ".0")));
  EXPECT_FALSE(fs::exists(dir / (".other.npy.vftmp." + dead + ".17")));
  EXPECT_TRUE(fs::is_directory(dir / (".d.vftmp." + dead + ".1")));
  for (const auto& name : kept) EXPECT_TRUE(fs::exists(dir / name)) << name;
}

// Temporaries name their host: on a directory shared between hosts (an MPI job's ranks on a
// cluster's file system), another host's PID says nothing here, so its temporaries are left alone
// while this host's stale ones go.
TEST(File, SweepsOnlyThisHostsStaleTemporaries) {
  ScratchDir dir;
  const std::string dead = std::to_string(dead_pid());
  // The tag this host writes: make a temporary and read it back from the directory.
  std::string tag;
  {
    FileTransaction t;
    t.stage(dir / "probe.bin", bytes_of("p"));
    for (const auto& e : fs::directory_iterator(dir.path())) {
      const std::string n = e.path().filename().string();
      const std::size_t at = n.find(".vftmp.");
      if (at != std::string::npos) tag = n.substr(at + 7, 8);
    }
  }
  ASSERT_EQ(tag.size(), 8u);
  const std::string other = tag == "00000000" ? "00000001" : "00000000";
  put(dir / (".x.bin.vftmp." + tag + "." + dead + ".0"), "stale, this host");
  put(dir / (".x.bin.vftmp." + other + "." + dead + ".0"), "another host's");
  put(dir / (".x.bin.vftmp.ZZZZZZZZ." + dead + ".0"), "not our pattern");
  write_file_atomic(dir / "y.bin", bytes_of("y"));
  EXPECT_FALSE(fs::exists(dir / (".x.bin.vftmp." + tag + "." + dead + ".0")));
  EXPECT_TRUE(fs::exists(dir / (".x.bin.vftmp." + other + "." + dead + ".0")));
  EXPECT_TRUE(fs::exists(dir / (".x.bin.vftmp.ZZZZZZZZ." + dead + ".0")));
}

TEST(File, RefusesFifoAsInputWithoutBlocking) {
  ScratchDir dir;
  const fs::path fifo = dir / "in.vox";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  auto attempt =
      std::async(std::launch::async, [&] { return io_error_of([&] { read_file(fifo); }); });
  if (attempt.wait_for(std::chrono::seconds(5)) == std::future_status::timeout) {
    // It blocked in open(): give it a writer so that the test ends, and fail.
    const int unblock = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    attempt.wait();
    if (unblock >= 0) ::close(unblock);
    FAIL() << "read_file blocked on a FIFO";
  }
  const std::string message = attempt.get();
  EXPECT_TRUE(message.starts_with(fifo.string())) << message;
  EXPECT_NE(message.find("not a regular file"), std::string::npos) << message;
  EXPECT_THROW(read_file_prefix(fifo, 4), IoError);
  EXPECT_THROW(regular_file_size(fifo), IoError);
  EXPECT_THROW(regular_file_size(dir.path()), IoError);
}

TEST(File, PrefixSizeAndLimit) {
  ScratchDir dir;
  const fs::path p = dir / "data.bin";
  write_file_atomic(p, std::vector<std::uint8_t>(2048, 9));
  EXPECT_EQ(regular_file_size(p), 2048u);
  EXPECT_EQ(read_file_prefix(p, 4), std::vector<std::uint8_t>(4, 9));
  EXPECT_EQ(read_file_prefix(p, 1 << 20).size(), 2048u);
  const std::string message = io_error_of([&] { read_file(p, 1024); });
  EXPECT_TRUE(message.starts_with(p.string())) << message;
  EXPECT_NE(message.find("file of 2.0 KiB exceeds the limit of 1.0 KiB"), std::string::npos)
      << message;
}

TEST(FileTransaction, UncommittedTouchesNothing) {
  ScratchDir dir;
  put(dir / "a.bin", "old a");
  {
    FileTransaction transaction;
    transaction.stage(dir / "a.bin", "new a");
    transaction.stage(dir / "b.bin", "new b");
    EXPECT_EQ(count_temporaries(dir.path()), 2);  // staged means written beside the target
  }
  EXPECT_EQ(read_file(dir / "a.bin"), bytes_of("old a"));
  EXPECT_FALSE(fs::exists(dir / "b.bin"));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(FileTransaction, CommitWritesAll) {
  ScratchDir dir;
  put(dir / "a.bin", "old a");
  FileTransaction transaction;
  transaction.stage(dir / "a.bin", "new a");
  transaction.stage(dir / "b.bin", bytes_of("new b"));
  transaction.commit();
  EXPECT_EQ(read_file(dir / "a.bin"), bytes_of("new a"));
  EXPECT_EQ(read_file(dir / "b.bin"), bytes_of("new b"));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(FileTransaction, FailedStageAbortsEverything) {
  ScratchDir dir;
  put(dir / "a.bin", "old a");
  {
    FileTransaction transaction;
    transaction.stage(dir / "a.bin", "new a");
    const fs::path missing = dir / "missing" / "b.bin";
    const std::string message = io_error_of([&] { transaction.stage(missing, "new b"); });
    EXPECT_TRUE(message.starts_with(missing.string())) << message;
    EXPECT_NE(message.find("does not exist"), std::string::npos) << message;
    EXPECT_EQ(count_temporaries(dir.path()), 0);  // the first one is gone already
    EXPECT_THROW(transaction.commit(), IoError);
  }
  EXPECT_EQ(read_file(dir / "a.bin"), bytes_of("old a"));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(FileTransaction, SignalRemovesTemporaries) {
  ScratchDir dir;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    // Only async-signal-safe exits from here: the child must not run the parent's test teardown.
    install_signal_cleanup();
    FileTransaction transaction;
    transaction.stage(dir / "a.bin", "staged a");
    transaction.stage(dir / "b.bin", "staged b");
    if (count_temporaries(dir.path()) != 2)
      ::_exit(3);  // nothing to clean: the test proves nothing
    ::raise(SIGTERM);
    ::_exit(4);  // not reached when the handler re-raises with the default action
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status)) << "child exited with " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_EQ(count_temporaries(dir.path()), 0);
  EXPECT_FALSE(fs::exists(dir / "a.bin"));
  EXPECT_FALSE(fs::exists(dir / "b.bin"));
}

TEST(File, CheckOutputPath) {
  ScratchDir dir;
  const auto refused = [](const fs::path& p, const std::string& cause) {
    const std::string message = io_error_of([&] { check_output_path(p); });
    EXPECT_TRUE(message.starts_with(p.string())) << p << ": " << message;
    EXPECT_NE(message.find(cause), std::string::npos) << p << ": " << message;
  };
  refused(dir / "missing" / "out.bin", "does not exist");
  refused(dir.path(), "is a directory");
  put(dir / "frozen.bin", "x");
  fs::permissions(dir / "frozen.bin", fs::perms::owner_read, fs::perm_options::replace);
  refused(dir / "frozen.bin", "read-only");
  put(dir / "plain", "x");
  refused(dir / "plain" / "out.bin", "");  // a file as a directory
  EXPECT_NO_THROW(check_output_path("-"));
  EXPECT_NO_THROW(check_output_path(dir / "new.bin"));
  EXPECT_FALSE(fs::exists(dir / "new.bin"));
  EXPECT_EQ(count_temporaries(dir.path()), 0);
}

TEST(File, SameFile) {
  ScratchDir dir;
  put(dir / "a.bin", "a");
  put(dir / "b.bin", "a");
  fs::create_symlink(dir / "a.bin", dir / "link.bin");
  EXPECT_TRUE(same_file(dir / "a.bin", dir / "link.bin"));
  EXPECT_TRUE(same_file(dir / "a.bin", dir / "." / "a.bin"));
  EXPECT_FALSE(same_file(dir / "a.bin", dir / "b.bin"));
  EXPECT_FALSE(same_file(dir / "a.bin", dir / "missing.bin"));
}
