#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "voxfield/error.h"
#include "voxfield/file.h"

using namespace voxfield;
namespace fs = std::filesystem;

TEST(File, AtomicWriteReplacesAndLeavesNoTemporaries) {
  const fs::path dir = fs::temp_directory_path() / ("voxfield_file_test_" + std::to_string(::getpid()));
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
  EXPECT_THROW(write_file_atomic("/nonexistent/voxfield/out.vox", std::vector<std::uint8_t>{1}), IoError);
  EXPECT_THROW(read_file(fs::temp_directory_path()), IoError);  // a directory
}
