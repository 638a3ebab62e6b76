// voxfield CLI — shared declarations of the subcommands (each in its own cmd_*.cpp).
//
// The CLI only parses arguments into settings and calls the library; every real piece of work is a
// library function. Exit codes: 0 success, 1 bad input or runtime error (message on stderr),
// 2 usage error.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "outputs.h"
#include "voxfield/vox.h"
#include "voxfield/world_io.h"

namespace voxfield::cli {

// A subcommand registers its options and returns the action to run once parsing succeeded.
using Action = std::function<int()>;

void add_info(CLI::App& app, Action& action);
void add_convert(CLI::App& app, Action& action);
void add_generate(CLI::App& app, Action& action);
void add_showcase(CLI::App& app, Action& action);
void add_field(CLI::App& app, Action& action);
void add_compare(CLI::App& app, Action& action);
void add_edit(CLI::App& app, Action& action);
void add_bench(CLI::App& app, Action& action);
void add_render(CLI::App& app, Action& action);
void add_mesh(CLI::App& app, Action& action);
void add_csg(CLI::App& app, Action& action);
void add_vectors(CLI::App& app, Action& action);
void add_bench_vectors(CLI::App* bench, Action& action);  // voxfield bench vectors

// A mistake in the command line found after CLI11's checks (options that contradict each other):
// exits 2 like every other usage error.
class UsageError : public InvalidArgument {
 public:
  using InvalidArgument::InvalidArgument;
};

// What the command is doing now ("loading world.vox"), so that a failure no library error
// describes (out of memory) still names the file and the step.
void set_activity(std::string what);
const std::string& activity();

// CLI11 validators whose messages read well: finite numbers (NaN and infinity refused), >= 0 or
// > 0, and camera specifications (checked for syntax when the command line is parsed).
CLI::Validator finite_number();
CLI::Validator finite_non_negative();
CLI::Validator finite_positive();
CLI::Validator camera_spec();

// "N" or "X,Y,Z" as given to --size.
Vec3i parse_size(const std::vector<int>& values);

// Milliseconds since `start`, for timing reports.
double ms_since(std::chrono::steady_clock::time_point start);

// A content hash (hash.h) as 16 hex digits, for stats files: results can be pinned beside times.
std::string hash_hex(std::uint64_t hash);

// Says on stderr what writing `world` to `out` leaves out (frame_left_out, world_io.h), if
// anything, so that nobody wonders where a frame went.
void note_frame_left_out(const World& world, const std::string& out);

}  // namespace voxfield::cli
