// voxfield mesh IN -o OUT: the iso-surface of a world (through its exact signed field, Euclidean
// unless --metric says otherwise)
// or of a float volume, as PLY, OBJ, STL or glTF binary.
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>

#include "backend_choice.h"
#include "cli.h"
#include "field_args.h"
#include "freed_pages.h"
#include "voxfield/gpu_mesh.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_optimize.h"
#include "voxfield/npy.h"
#include "voxfield/parallel.h"

namespace voxfield::cli {
namespace {

struct MeshSettings {
  std::string in, out, stats, algorithm = "mc", inside = "below", backend = "cpu", grid;
  std::optional<double> iso;
  std::optional<std::string> metric;
  std::vector<double> spacing;
  int chunk = 32, threads = 0;
  std::optional<double> simplify, simplify_error;
  bool optimize = false;
};

bool is_float(DType t) {
  return t == DType::kFloat32 || t == DType::kFloat64;
}

int run_mesh(const MeshSettings& s) {
  check_grid_input(s.in, s.grid);
  MeshOptions options;
  options.algorithm = parse_mesher(s.algorithm);
  options.chunk_edge = s.chunk;
  if (s.inside != "below" && s.inside != "above")
    throw UsageError("--inside must be below or above, not " + s.inside);
  options.inside_above = s.inside == "above";
  options.iso = s.iso.value_or(0);
  if (!s.spacing.empty() && s.spacing.size() != 3)
    throw UsageError("--spacing takes three values: sx,sy,sz");
  const MeshFormat format = mesh_format_of(s.out);
  Outputs outputs({s.in});
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  if (s.backend != "cpu" && options.algorithm != Mesher::kMarchingCubes)
    throw UsageError("--backend " + s.backend +
                     ": the GPU meshes with marching cubes only (--algorithm mc); surface nets "
                     "and dual contouring run on the CPU");

  auto start = std::chrono::steady_clock::now();
  set_activity("loading " + s.in);
  std::optional<NpyVolume> npy;
  if (std::filesystem::path(s.in).extension() == ".npy") npy = read_npy(s.in);
  const bool volume_input = npy && is_float(npy->dtype);
  if (volume_input && s.metric)
    throw UsageError("--metric is for worlds (meshed through their exact signed field); " + s.in +
                     " is a float volume, meshed as it is");
  const double load_ms = ms_since(start);
  Mesh mesh;
  std::int64_t chunks = 0;
  std::optional<gpu::GpuMeshStats> gpu_stats;
  set_activity("meshing " + s.in);
  double mesh_ms = 0;
  if (volume_input) {
    const std::vector<float> values = float_samples(*npy, s.in);
    // The raw bytes are converted: freed before meshing, they no longer add to the peak memory,
    // and their pages hold the mesh's first arrays (freed_pages.h), until the mesh is made.
    std::optional<app::KeepFreedPages> keep_freed_pages(std::in_place);
    std::vector<std::uint8_t>().swap(npy->bytes);
    ScalarVolume volume{npy->dims, values.data()};
    if (!s.spacing.empty()) volume.spacing_units = {s.spacing[0], s.spacing[1], s.spacing[2]};
    for (int a = 0; a < 3; ++a)
      chunks = (a ? chunks : 1) * ((npy->dims[a] - 1 + s.chunk - 1) / std::max(1, s.chunk));
    std::shared_ptr<gpu::Context> gpu_context;
    if (s.backend != "cpu") gpu_context = choose_backend(s.backend);
    start = std::chrono::steady_clock::now();
    if (gpu_context) {
      try {
        gpu::GpuMeshStats st;
        mesh = gpu::marching_cubes(*gpu_context, volume, options, {}, &st);
        gpu_stats = st;
      } catch (const GpuUnavailable& e) {
        // auto promises the CPU where the GPU cannot: a device without shaderFloat64, say.
        if (s.backend != "auto") throw;
        std::cerr << "voxfield: " << e.what() << "; using the cpu backend\n";
      }
    }
    if (!gpu_stats) mesh = mesh_volume(volume, options);
    mesh_ms = ms_since(start);
    keep_freed_pages.reset();
  } else {
    if (s.backend != "cpu")
      throw UsageError("--backend " + s.backend +
                       ": worlds are meshed on the CPU (their surface, colours and normals come "
                       "from the exact field there); the GPU meshes float volumes");
    if (s.inside != "below" || !s.spacing.empty())
      throw UsageError(
          "--inside and --spacing are for float volumes; a world's solid voxels are inside, one "
          "unit per voxel");
    LoadOptions lo;
    lo.vdb_grid = s.grid;
    const World world = npy ? world_from_npy(*npy, s.in) : load_world(s.in, lo).world;
    // mesh_world's domain: the content grown past the surface (by more for an offset surface).
    const Vec3i size = world.voxels.content_bounds().grown(mesh_world_margin(options.iso)).size();
    for (int a = 0; a < 3; ++a)
      chunks = (a ? chunks : 1) * ((size[a] - 1 + s.chunk - 1) / std::max(1, s.chunk));
    start = std::chrono::steady_clock::now();
    mesh = mesh_world(world, options, parse_metric(s.metric.value_or("euclidean")));
    mesh_ms = ms_since(start);
  }
  std::optional<SimplifyStats> simplified;
  double simplify_ms = 0;
  if (s.simplify || s.simplify_error) {
    set_activity("simplifying the mesh of " + s.in);
    SimplifyOptions so;
    so.triangle_ratio = s.simplify.value_or(0.0);  // an error limit alone: as far as it allows
    so.max_error_units = s.simplify_error.value_or(0);
    start = std::chrono::steady_clock::now();
    simplified.emplace();
    mesh = simplify_mesh(mesh, so, &*simplified);
    simplify_ms = ms_since(start);
  }
  if (s.optimize) optimize_mesh(mesh);
  set_activity("writing " + s.out);
  start = std::chrono::steady_clock::now();
  outputs.stage(s.out, encode_mesh(mesh, format));
  const double write_ms = ms_since(start);
  const MeshStats st = mesh_stats(mesh);
  if (!s.stats.empty()) {
    nlohmann::json j;
    j["input"] = s.in;
    j["output"] = s.out;
    j["algorithm"] = mesher_name(options.algorithm);
    j["ms"] = mesh_ms;
    j["phases_ms"] = {
        {"load", load_ms}, {"mesh", mesh_ms}, {"simplify", simplify_ms}, {"encode", write_ms}};
    if (simplified)
      j["simplify"] = {{"triangles_before", simplified->triangles_before},
                       {"triangles_after", simplified->triangles_after},
                       {"error_units", simplified->error_units}};
    j["optimized"] = s.optimize;
    j["backend"] = gpu_stats ? "vulkan" : "cpu";
    if (gpu_stats)
      j["gpu"] = {{"dispatches", gpu_stats->dispatches},
                  {"submits", gpu_stats->submits},
                  {"fence_waits", gpu_stats->fence_waits},
                  {"bytes_uploaded", gpu_stats->bytes_uploaded},
                  {"bytes_downloaded", gpu_stats->bytes_downloaded},
                  {"pyramid_levels", gpu_stats->pyramid_levels}};
    j["threads"] = max_threads();
    if (!gpu_stats) {  // the CPU's partition; the GPU meshes the lattice whole
      j["chunk_edge"] = s.chunk;
      j["chunks"] = chunks;
    }
    j["vertices"] = st.vertices;
    j["triangles"] = st.triangles;
    j["watertight"] = st.watertight();
    j["boundary_edges"] = st.boundary_edges;
    j["nonmanifold_edges"] = st.nonmanifold_edges;
    j["euler_characteristic"] = st.euler_characteristic;
    j["area_units2"] = st.area_units2;
    j["volume_units3"] = st.signed_volume_units3;
    outputs.stage_json(s.stats, j);
  }
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << st.triangles << " triangles, " << st.vertices
            << " vertices, " << mesher_name(options.algorithm) << ", " << std::lround(mesh_ms)
            << " ms" << (st.watertight() ? ", watertight" : "") << ")\n";
  return 0;
}

}  // namespace

void add_mesh(CLI::App& app, Action& action) {
  auto s = std::make_shared<MeshSettings>();
  CLI::App* cmd =
      app.add_subcommand("mesh",
                         "Mesh the surface of a world (.vox, .vfw, integer .npy: through its exact "
                         "signed distance field) or the iso-surface of a float .npy volume");
  cmd->add_option("IN", s->in,
                  "input world (.vox, .npy, .vfw or .vdb) or float32/float64 .npy volume")
      ->required();
  add_grid_option(cmd, s->grid);
  cmd->add_option("-o,--output", s->out, "output .ply, .obj, .stl or .glb (written atomically)")
      ->required();
  cmd->add_option("--algorithm", s->algorithm,
                  "mc (marching cubes), sn (surface nets) or dc (dual contouring)")
      ->check(
          CLI::IsMember({"mc", "sn", "dc", "marching-cubes", "surface-nets", "dual-contouring"}));
  cmd->add_option("--iso", s->iso,
                  "iso value (default 0): of a float volume; of a world, the offset surface that "
                  "many voxels out from its solid voxels (negative: in; |iso| >= 1)")
      ->check(CLI::Number);
  cmd->add_option("--metric", s->metric,
                  "a world's field: euclidean (default), chebyshev or manhattan — the shape of "
                  "its offset surfaces (at iso 0 all give the voxels' surface)")
      ->check(CLI::IsMember({"euclidean", "chebyshev", "manhattan"}));
  cmd->add_option("--inside", s->inside,
                  "which values of a float volume are inside: below (default) or above iso")
      ->check(CLI::IsMember({"below", "above"}));
  cmd->add_option(
         "--spacing", s->spacing,
         "sample spacing of a float volume: sx,sy,sz (sample a[x,y,z] at (x,y,z) * spacing)")
      ->delimiter(',')
      ->check(finite_positive());
  cmd->add_option("--chunk", s->chunk, "cells per chunk edge (2..256, default 32)")
      ->check(CLI::Range(2, 256));
  cmd->add_option("--threads", s->threads, "threads (default: all)")->check(CLI::Range(1, 1024));
  cmd->add_option("--simplify", s->simplify,
                  "keep about this fraction of the triangles (0 < R <= 1; meshoptimizer)")
      ->check(CLI::Range(1e-6, 1.0));
  cmd->add_option("--simplify-error", s->simplify_error,
                  "simplify no farther than this from the surface, in output units (default 1 % of "
                  "the extent)")
      ->check(finite_positive());
  cmd->add_flag("--optimize", s->optimize,
                "reorder triangles and vertices for the GPU's vertex cache (meshoptimizer)");
  cmd->add_option("--stats", s->stats, "write counts, topology and timings as JSON");
  cmd->add_option("--backend", s->backend,
                  "cpu (default), vulkan (any Vulkan device, software included) or auto (a "
                  "hardware GPU if there is one, else the CPU): vulkan runs marching cubes of a "
                  "float volume with a HistoPyramid, the same triangles as the CPU's (--chunk "
                  "and --threads are the CPU's)")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->callback([s, &action] { action = [s] { return run_mesh(*s); }; });
}

}  // namespace voxfield::cli
