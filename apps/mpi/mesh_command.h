// voxfield-mpi mesh: the iso-surface of a float .npy volume, or the surface of a world (.vox, .vfw,
// .vdb, integer .npy), meshed over the ranks of a job, each reading only the planes its chunk
// layers need, every rank writing its share of the file (mpi.h's write_mesh_volume and
// write_world_mesh).
#pragma once

#include <mpi.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "read_option.h"
#include "voxfield/file.h"
#include "voxfield/mpi.h"

namespace voxfield::mpi_cli {

struct MeshSettings {
  std::string in, out, stats, algorithm = "mc", inside = "below", balance = "content";
  double iso = 0;
  std::vector<double> spacing;
  std::optional<std::string> metric;  // worlds only
  ReadSettings read;                  // worlds only (--read, --grid)
  int chunk = 32, threads = 0;
};

// The subcommand and its options, as `voxfield mesh` names them.
CLI::App* add_mesh_command(CLI::App& app, MeshSettings& s);
int run_mesh(MPI_Comm comm, const MeshSettings& s);
// The world's side of run_mesh (world_mesh_command.cpp).
int run_world_mesh(MPI_Comm comm, const MeshSettings& s);

// voxfield-mpi edit --mesh: the edited world's surface — each rank's slab of `world`, which holds
// mesh_world_slab_reach(algorithm) slices beyond it — staged in `into` (rank 0's; every rank writes
// its share): the file `voxfield mesh` writes for the edited world. Returns what --stats reports.
nlohmann::json write_edited_world_mesh(MPI_Comm comm, const mpi::SlabPartition& partition,
                                       const World& world, Mesher algorithm,
                                       const std::string& path, FileTransaction* into);

// The end of either: rank 0 stages --stats (the summary's counts and census, `ms` the mesh made
// and written since `t_mesh` (MPI_Wtime), the exchange, peak memory, and `extra`'s fields) in
// `outputs` and commits them; every rank takes part. Says what was written on rank 0.
int finish_mesh(MPI_Comm comm, const MeshSettings& s, const mpi::MeshFileSummary& mesh,
                double t_mesh, const mpi::ExchangeStats& ex,
                std::optional<FileTransaction>& outputs, nlohmann::json extra);

}  // namespace voxfield::mpi_cli
