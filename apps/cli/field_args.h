// voxfield CLI — the distance-field options shared by `field`, `compare` (and later `edit`).
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "voxfield/algorithms.h"
#include "voxfield/file.h"
#include "voxfield/npy.h"
#include "voxfield/world_io.h"

namespace voxfield::cli {

struct FieldArgs {
  std::string metric = "manhattan";
  bool is_signed = false;
  double max_distance = 0;
  std::string storage = "f32";
  std::vector<double> spacing;
  std::vector<int> focus;
  int chunk_edge = 32;
  int threads = 0;
  std::string grid;  // --grid (add_grid_option): a .vdb input's grid

  void add_to(CLI::App* cmd);
  // How the input world is loaded: the chunk edge and --grid.
  LoadOptions load_options() const;
  DistanceOptions options() const;
  // The settings every stats file starts with: metric, signed, max_distance, storage, dims,
  // threads, chunk.
  nlohmann::json describe(const DistanceOptions& o, Vec3i dims) const;
  std::optional<Box3i> focus_box() const;
};

// --grid NAME: which grid of a .vdb input holds the world (LoadOptions::vdb_grid); without it, the
// first of voxfield's kind "world", else the first Int32 grid, else the first.
void add_grid_option(CLI::App* cmd, std::string& grid);
// Refuses (UsageError, before anything is read) a --grid for an input that is not a .vdb file.
void check_grid_input(const std::string& in, const std::string& grid);

// Every algorithm's name, for --algorithm's check.
std::vector<std::string> algorithm_names();
// Whether an algorithm gives nearest sites with these options (asked of the algorithm itself, on
// a 3^3 world: no table to fall out of date).
bool algorithm_tracks_sites(const AlgorithmOptions& a, const DistanceOptions& o);

// Resident-set high-water mark of this process, in bytes.
std::size_t peak_rss_bytes();

nlohmann::json error_json(const FieldError& e);

// The field's values over `box` as an .npy volume of the storage's dtype.
NpyVolume field_volume(const DistanceField& f, const Box3i& box);
// Nearest-site offsets as int16 a[x, y, z, 3]; -32768 where there is none.
NpyVolume sites_volume(const Grid<SiteOffset>& g, const Box3i& box);

}  // namespace voxfield::cli
