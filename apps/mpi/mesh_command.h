// voxfield-mpi mesh: the iso-surface of a float .npy volume meshed over the ranks of a job, each
// reading only the sample planes its chunk layers need (mpi.h's mesh_volume), written by rank 0.
#pragma once

#include <mpi.h>

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace voxfield::mpi_cli {

struct MeshSettings {
  std::string in, out, stats, algorithm = "mc", inside = "below", balance = "content";
  double iso = 0;
  std::vector<double> spacing;
  int chunk = 32, threads = 0;
};

// The subcommand and its options, as `voxfield mesh` names them.
CLI::App* add_mesh_command(CLI::App& app, MeshSettings& s);
int run_mesh(MPI_Comm comm, const MeshSettings& s);

}  // namespace voxfield::mpi_cli
