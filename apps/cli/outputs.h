// voxfield CLI — a command's outputs, checked before any work and written all or nothing.
//
// A command declares every output path it was given (expect) before it loads or computes
// anything: each is checked to be writable and not to be one of the inputs, so that a mistake is
// reported at once and costs nothing. Results are then staged (written to temporaries beside their
// targets) and committed together at the very end: a command that fails anywhere leaves no output
// and every target as it was.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "voxfield/file.h"
#include "voxfield/world_io.h"

namespace voxfield::cli {

class Outputs {
 public:
  explicit Outputs(std::vector<std::string> inputs = {}) : inputs_(std::move(inputs)) {}

  // Checks an output given by `option` (e.g. "--stats"); an empty path is "not asked for". Throws
  // IoError / InvalidArgument naming the option and the path. `may_be_input`: the command reads
  // its input whole before writing (convert), so writing over it is safe.
  void expect(const std::string& path, const std::string& option, bool may_be_input = false);
  // The same for a world file, whose format is checked from its extension too.
  void expect_world(const std::string& path, const std::string& option, bool may_be_input = false);

  void stage(const std::string& path, std::span<const std::uint8_t> bytes) {
    tx_.stage(path, bytes);
  }
  void stage(const std::string& path, std::string_view text) { tx_.stage(path, text); }
  void stage_json(const std::string& path, const nlohmann::json& j);
  void commit() { tx_.commit(); }

 private:
  std::vector<std::string> inputs_;
  std::vector<std::string> outputs_;
  FileTransaction tx_;
};

}  // namespace voxfield::cli
