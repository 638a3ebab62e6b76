// voxfield-mpi: --read, who opens a command's input (mpi::ReadBy), and --grid, a .vdb input's grid
// by name, for field, edit and render.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "voxfield/mpi.h"

namespace voxfield::mpi_cli {

struct ReadSettings {
  std::string by = "every";  // --read
  std::string grid;          // --grid
};

inline void add_read_options(CLI::App* cmd, ReadSettings& read) {
  cmd->add_option("--read", read.by,
                  "who opens IN: every rank (its own part; a file system every rank sees) or "
                  "rank0 (rank 0 alone, which sends the others their parts)")
      ->check(CLI::IsMember({"every", "rank0"}))
      ->capture_default_str();
  cmd->add_option("--grid", read.grid,
                  "a .vdb input's grid to read the world from, by name (default: voxfield's "
                  "world grid, else the first int32 grid, else the first)");
}

inline mpi::SlabReadOptions slab_read_options(const ReadSettings& read) {
  mpi::SlabReadOptions o;
  o.read_by = read.by == "rank0" ? mpi::ReadBy::kRankZero : mpi::ReadBy::kEveryRank;
  o.vdb_grid = read.grid;
  return o;
}
// How a slab was read, for --stats: what load_world_slab did, not what was asked.
inline const char* read_name(mpi::ReadBy by) {
  return by == mpi::ReadBy::kRankZero ? "rank0" : "every";
}

}  // namespace voxfield::mpi_cli
