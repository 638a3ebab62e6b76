// voxfield CLI — outputs checked first, written all or nothing (outputs.h), and small helpers.
#include "outputs.h"

#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli.h"

namespace voxfield::cli {

void Outputs::expect(const std::string& path, const std::string& option, bool may_be_input) {
  if (path.empty()) return;
  check_output_path(path);
  if (!may_be_input) {
    for (const std::string& in : inputs_) {
      if (same_target(path, in)) {
        throw InvalidArgument(option + " " + path +
                              " is also an input of this command; writing it would destroy " + in +
                              " (choose another output)");
      }
    }
  }
  for (const std::string& out : outputs_) {
    if (same_target(path, out))
      throw InvalidArgument(option + " " + path + " is given as two outputs");
  }
  outputs_.push_back(path);
}

void Outputs::expect_world(const std::string& path, const std::string& option, bool may_be_input) {
  if (path.empty()) return;
  (void)world_format_of(path);
  expect(path, option, may_be_input);
}

void Outputs::stage_json(const std::string& path, const nlohmann::json& j) {
  if (path.empty()) return;  // not asked for
  tx_.stage(path, std::string_view(j.dump(2) + "\n"));
}

void note_frame_left_out(const World& world, const std::string& out) {
  const std::string note = frame_left_out(world, out);
  if (!note.empty()) std::cerr << "voxfield: note: " << note << "\n";
}

std::string hash_hex(std::uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace voxfield::cli
