// voxfield-mpi render: a frame of a world split over the ranks of a job, each rank walking the rays
// that cross its slab (mpi.h's render), written by rank 0 as the PNG `voxfield render` writes.
#pragma once

#include <mpi.h>

#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "read_option.h"

namespace voxfield::mpi_cli {

struct RenderSettings {
  std::string in, out, stats, camera = "auto", view = "shaded", metric = "manhattan",
                              skip = "distance";
  int width = 1280, height = 720, chunk = 32, threads = 0, repeat = 1;
  std::optional<int> slice;  // --slice: the distance view's cut plane
  bool no_shadows = false, no_ao = false;
  double fog = 0;
  std::string camera_frame = "voxels";
  ReadSettings read;  // --read and --grid
};

// The subcommand and its options, as `voxfield render` names them.
CLI::App* add_render_command(CLI::App& app, RenderSettings& s);
int run_render(MPI_Comm comm, const RenderSettings& s);

}  // namespace voxfield::mpi_cli
