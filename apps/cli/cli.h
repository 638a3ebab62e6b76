// voxfield CLI — shared declarations of the subcommands (each in its own cmd_*.cpp).
//
// The CLI only parses arguments into settings and calls the library; every real piece of work is a
// library function. Exit codes: 0 success, 1 bad input or runtime error (message on stderr),
// 2 usage error.
#pragma once

#include <CLI/CLI.hpp>
#include <chrono>
#include <optional>
#include <vector>
#include <filesystem>
#include <functional>
#include <string>

#include "voxfield/vox.h"

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

// A world read from any supported file, with what the file said about itself.
struct LoadedWorld {
  World world;
  std::string format;       // "vox" or "npy"
  Box3i extent;             // the volume the file declares (npy shape, model or scene box)
  std::string description;  // one line: format, version, dtype...
  std::optional<VoxFileInfo> vox;
};

// Loads a .vox or .npy file, chosen by extension. Throws voxfield::Error.
LoadedWorld load_world(const std::filesystem::path& path, int chunk_edge);
// Writes a world as .vox or .npy (chosen by extension); for .npy the box `extent` united with
// the content is written. Throws voxfield::Error.
void save_world(const World& world, const Box3i& extent, const std::filesystem::path& path);

// "N" or "X,Y,Z" as given to --size.
Vec3i parse_size(const std::vector<int>& values);

// Milliseconds since `start`, for timing reports.
double ms_since(std::chrono::steady_clock::time_point start);

}  // namespace voxfield::cli
