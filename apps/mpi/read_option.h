// voxfield-mpi: --read, who opens a command's input (mpi::ReadBy), for field, edit and render.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "voxfield/mpi.h"

namespace voxfield::mpi_cli {

inline void add_read_option(CLI::App* cmd, std::string& read) {
  cmd->add_option("--read", read,
                  "who opens IN: every rank (its own part; a file system every rank sees) or "
                  "rank0 (rank 0 alone, which sends the others their parts)")
      ->check(CLI::IsMember({"every", "rank0"}))
      ->capture_default_str();
}

inline mpi::ReadBy read_by(const std::string& read) {
  return read == "rank0" ? mpi::ReadBy::kRankZero : mpi::ReadBy::kEveryRank;
}
// How a slab was read, for --stats: what load_world_slab did, not what was asked.
inline const char* read_name(mpi::ReadBy by) {
  return by == mpi::ReadBy::kRankZero ? "rank0" : "every";
}

}  // namespace voxfield::mpi_cli
