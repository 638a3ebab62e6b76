// voxfield field IN -o OUT.npy|OUT.vdb [options]: a distance field of a world, written as .npy or
// as an OpenVDB grid (a level set when signed; vdb.h); or the signed distance field of a triangle
// mesh (.obj, .ply, .stl, .off) at --voxel-size, in the mesh's units (mesh_voxelize.h).
#include <algorithm>
#include <cctype>
#include <chrono>
#include <fstream>
#include <iostream>

#include "backend_choice.h"
#include "cli.h"
#include "field_args.h"
#include "progress.h"
#include "voxfield/dissertation_format.h"
#include "voxfield/gpu_distance.h"
#include "voxfield/mesh_read.h"
#include "voxfield/npy.h"
#include "voxfield/parallel.h"
#include "voxfield/vdb.h"

namespace voxfield::cli {
namespace {

struct FieldSettings {
  std::string in, out, sites, stats, packed;
  std::string algorithm = "exact";
  std::string backend = "cpu";
  FieldArgs field;
  double voxel_size = 0;
  bool metric_given = false;
};

// A mesh's field: always signed (by the winding number) and Euclidean, in the mesh's units, f32.
// The output's extension, lower case (".npy", ".vdb", ...).
int run_mesh_field(const FieldSettings& s, Outputs& outputs) {
  const auto refuse = [&](bool bad, const std::string& what) {
    if (bad) throw UsageError(s.in + ": " + what);
  };
  refuse(!(s.voxel_size > 0), "a mesh needs --voxel-size (the voxels' edge in its units)");
  refuse(s.metric_given && s.field.metric != "euclidean",
         "a mesh's field is Euclidean (--metric " + s.field.metric + ")");
  refuse(s.field.storage != "f32", "a mesh's field is stored as f32, in the mesh's units");
  refuse(!s.field.spacing.empty(), "--spacing: a mesh's voxels are cubes of --voxel-size");
  refuse(s.algorithm != "exact" || s.backend != "cpu" || !s.field.focus.empty(),
         "a mesh's field has one algorithm, on the CPU (no --algorithm, --backend or --focus)");
  refuse(!s.sites.empty() || !s.packed.empty(), "--sites and --packed apply to worlds");
  refuse(lowercase_extension(s.out) != ".npy", "a mesh's field is written as .npy");
  set_activity("reading " + s.in);
  const TriangleMesh mesh = read_mesh(s.in);
  MeshDistanceOptions o;
  o.voxel_size = s.voxel_size;
  o.max_distance = s.field.max_distance;
  o.interrupter = progress();
  set_activity("computing the field of " + s.in);
  const auto start = std::chrono::steady_clock::now();
  MeshDistanceField f = mesh_distance_field(mesh, o);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  set_activity("writing " + s.out);
  const Vec3i dims = f.box.size();
  outputs.stage(s.out, encode_npy(make_npy(DType::kFloat32, dims, f.values.data())));
  const std::array<double, 3> first{(f.box.begin.x + 0.5) * f.voxel_size,
                                    (f.box.begin.y + 0.5) * f.voxel_size,
                                    (f.box.begin.z + 0.5) * f.voxel_size};
  if (!s.stats.empty()) {
    outputs.stage_json(
        s.stats,
        nlohmann::json{{"input", "mesh"},
                       {"triangles", mesh.triangles.size()},
                       {"vertices", mesh.positions.size()},
                       {"voxel_size", f.voxel_size},
                       {"dims", {dims.x, dims.y, dims.z}},
                       {"first_sample", first},
                       {"band_voxels", f.band_voxels},
                       {"max_distance", s.field.max_distance},
                       {"ms", ms},
                       {"peak_rss_mb", static_cast<double>(peak_rss_bytes()) / 1048576.0}});
  }
  outputs.commit();
  std::cerr << "voxfield: signed distance field of " << mesh.triangles.size() << " triangles, "
            << dims.x << "x" << dims.y << "x" << dims.z << " samples of " << f.voxel_size
            << " from (" << first[0] << ", " << first[1] << ", " << first[2] << "), in " << ms
            << " ms, wrote " << s.out << "\n";
  return 0;
}

int run_field(const FieldSettings& s) {
  check_grid_input(s.in, s.field.grid);
  std::optional<ThreadLimit> limit;
  if (s.field.threads > 0) limit.emplace(s.field.threads);
  // Everything that can be wrong with the options is found before the world is loaded.
  Outputs outputs({s.in});
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");
  if (mesh_input_format_of(s.in)) return run_mesh_field(s, outputs);
  if (s.voxel_size != 0)
    throw UsageError("--voxel-size applies to mesh inputs (.obj, .ply, .stl, .off)");
  const bool vdb_output = lowercase_extension(s.out) == ".vdb";  // else .npy
  outputs.expect(s.sites, "--sites");
  outputs.expect(s.packed, "--packed");
  DistanceOptions o = s.field.options();
  o.interrupter = progress();  // a progress bar on a terminal for fields that take a while
  o.nearest_sites = !s.sites.empty();
  AlgorithmOptions a;
  a.algorithm = parse_algorithm(s.algorithm);
  a.focus = s.field.focus_box();
  if (a.algorithm == Algorithm::kLod && !a.focus) throw UsageError("--algorithm lod needs --focus");
  if (o.nearest_sites && !algorithm_tracks_sites(a, o)) {
    throw InvalidArgument("--sites: the " + s.algorithm +
                          " algorithm does not track nearest sites");
  }
  set_activity("loading " + s.in);
  const LoadedWorld in = load_world(s.in, s.field.load_options());
  o.domain = in.extent;  // the output covers the input's volume, indexed like it
  if (o.domain->empty()) throw InvalidArgument(s.in + ": the input holds no volume");
  // A .vdb level set holds world distances: a world with anisotropic voxels (a scan's 1 x 1 x 3
  // mm) is measured in its voxel size unless --spacing says otherwise. Isotropic voxels need no
  // spacing (the writer scales voxels to world units), nor does a .npy (values in voxels).
  const Vec3d size = in.world.frame.voxel_size_world;
  // (On the CPU: the GPU backend measures in voxels only, and its refusal would name a spacing
  // nobody gave; the writer's own refusal names --spacing.)
  if (vdb_output && s.backend == "cpu" && s.field.spacing.empty() &&
      o.metric == Metric::kEuclidean && !(size.x == size.y && size.y == size.z)) {
    o.spacing = {size.x, size.y, size.z};
    std::cerr << "voxfield: measuring in the world's voxel size " << size.x << " x " << size.y
              << " x " << size.z << " (--spacing), so that " << s.out
              << " holds distances in its units (--max-distance too)\n";
  }
  if (vdb_output) check_vdb_field_output(o, in.world.frame, s.out);  // before the field's time
  AlgorithmStats stats;
  const auto gpu_context = choose_backend(s.backend);
  std::vector<gpu::PassTiming> pass_timings;
  std::optional<DistanceField> computed;
  set_activity("computing the field of " + s.in);
  if (gpu_context) {
    computed = gpu::compute_distance_field(*gpu_context, in.world, o, a, &stats, &pass_timings);
  } else {
    computed = compute_distance_field(in.world, o, a, &stats);
  }
  const DistanceField& f = *computed;

  set_activity("writing " + s.out);
  if (vdb_output) {
    outputs.stage(s.out, encode_vdb_field(f));
  } else {
    outputs.stage(s.out, encode_npy(field_volume(f, f.domain)));
  }
  if (!s.sites.empty()) {
    if (!f.sites)
      throw InvalidArgument("--sites: the " + s.algorithm +
                            " algorithm does not track nearest sites");
    outputs.stage(s.sites, encode_npy(sites_volume(*f.sites, f.domain)));
  }
  if (!s.packed.empty()) {
    const auto packed = pack_dissertation_format(in.world, f, f.domain);
    outputs.stage(s.packed, encode_npy(make_npy(DType::kUInt32, f.domain.size(), packed.data())));
  }
  const Vec3i d = f.domain.size();
  nlohmann::json j = s.field.describe(o, d);
  j.update(nlohmann::json{{"algorithm", s.algorithm},
                          {"ms", stats.ms},
                          {"mvox_per_s", static_cast<double>(f.domain.volume()) / (stats.ms * 1e3)},
                          {"passes", stats.passes},
                          {"iterations", stats.iterations},
                          {"field_hash", hash_hex(content_hash(f))},
                          {"peak_rss_mb", static_cast<double>(peak_rss_bytes()) / 1048576.0}});
  j["backend"] = gpu_context ? "vulkan" : "cpu";
  if (gpu_context) {
    j["gpu"] = gpu_json(*gpu_context);
    j["gpu"]["passes"] = pass_timings_json(pass_timings);
  }
  if (a.algorithm != Algorithm::kExact) {
    DistanceOptions exact_o = o;
    exact_o.nearest_sites = false;
    j["error"] = error_json(compare_fields(f, compute_distance_field(in.world, exact_o), in.world));
  }
  if (!s.stats.empty()) outputs.stage_json(s.stats, j);
  outputs.commit();
  std::cerr << "voxfield: " << s.algorithm << " " << metric_name(o.metric) << " field of " << d.x
            << "x" << d.y << "x" << d.z << " in " << stats.ms << " ms, wrote " << s.out << "\n";
  return 0;
}

}  // namespace

void add_field(CLI::App& app, Action& action) {
  auto s = std::make_shared<FieldSettings>();
  CLI::App* cmd = app.add_subcommand(
      "field",
      "Compute a distance field and write it as .npy (a[x, y, z], like the input) or .vdb");
  cmd->add_option("IN", s->in, "input .vox, .npy, .vfw or .vdb, or a mesh: .obj, .ply, .stl, .off")
      ->required();
  cmd->add_option("-o,--output", s->out,
                  "output .npy, or .vdb (an OpenVDB float grid: a level set when signed)")
      ->required();
  s->field.add_to(cmd);
  add_grid_option(cmd, s->field.grid);
  cmd->add_option("--backend", s->backend,
                  "cpu (default), vulkan (any Vulkan device, software included) or auto "
                  "(a hardware GPU if there is one, else the CPU)")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->add_option("--algorithm", s->algorithm,
                  "exact, brute, brute-chunked, fim, jfa-seed, jfa, jfa+1, jfa+2, hybrid, lod")
      ->check(CLI::IsMember(algorithm_names()))
      ->capture_default_str();
  cmd->add_option("--sites", s->sites,
                  "also write nearest-site offsets as int16 a[x, y, z, 3] to this .npy");
  cmd->add_option("--packed", s->packed,
                  "also write the dissertation's packed uint32 voxels to this .npy");
  cmd->add_option("--stats", s->stats, "write timing (ms: compute only) and error figures as JSON");
  cmd->add_option("--voxel-size", s->voxel_size,
                  "for a mesh: the samples' spacing in its units (the field is signed by the "
                  "winding number, Euclidean, f32, in the mesh's units)");
  cmd->callback([s, cmd, &action] {
    s->metric_given = cmd->get_option("--metric")->count() > 0;
    action = [s] { return run_field(*s); };
  });
}

}  // namespace voxfield::cli
