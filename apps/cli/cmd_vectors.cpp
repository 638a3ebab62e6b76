// voxfield vectors SOURCES.json -o OUT: a vector-field volume texture from moving sources
// (docs/vectors.md), as float32 .npy, Unreal .fga, Unity .vf, OpenVDB .vdb or a visualiser picture.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>

#include "cli.h"
#include "vector_backend.h"
#include "voxfield/gpu_vectors.h"
#include "voxfield/png.h"
#include "voxfield/vdb.h"
#include "voxfield/vector_files.h"
#include "voxfield/vector_world.h"
#include "voxfield/vectors.h"

namespace voxfield::cli {
namespace {

struct VectorSettings {
  std::string sources, out, stats, algorithm = "splat", rule = "strongest", storage = "rgba8";
  std::string backend = "cpu";
  std::vector<int> resolution{64, 64, 64};
  std::vector<double> box, rotation;
  double dt_s = 1.0 / 60, decay_per_s = 1.0;
  std::optional<double> reach;  // a world input: the reach of its solids
  int width = 640, height = 480;
};

enum class OutKind { kNpy, kFga, kVf, kVdb, kPng };

OutKind out_kind(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".npy") return OutKind::kNpy;
  if (ext == ".fga") return OutKind::kFga;
  if (ext == ".vf") return OutKind::kVf;
  if (ext == ".vdb") return OutKind::kVdb;
  if (ext == ".png") return OutKind::kPng;
  throw UsageError("-o " + path + ": the output must be .npy, .fga, .vf, .vdb or .png");
}

// The box of every source's segment grown by its radius (and a tenth on each side), when --box is
// not given.
VectorVolume volume_around(const VectorSourceFrames& f, Vec3i resolution) {
  double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                  std::numeric_limits<double>::max()};
  double hi[3] = {-lo[0], -lo[1], -lo[2]};
  bool any = false;
  for (const auto& frame : f.frames)
    for (const VectorSource& s : frame)
      for (const Vec3d& p : {s.position, s.previous})
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], p[a] - s.radius);
          hi[a] = std::max(hi[a], p[a] + s.radius);
          any = true;
        }
  if (!any) throw UsageError("the sources file holds no source: give the volume with --box");
  VectorVolume v;
  v.resolution = resolution;
  for (int a = 0; a < 3; ++a) {
    const double margin = 0.1 * (hi[a] - lo[a]);
    v.centre[a] = 0.5 * (lo[a] + hi[a]);
    v.size[a] = hi[a] - lo[a] + 2 * margin;
  }
  return v;
}

// A world as input: the flow away from its solids, over its content box grown by the reach.
int run_world_vectors(const VectorSettings& s, OutKind kind, Outputs& outputs) {
  if (!s.box.empty() || !s.rotation.empty())
    throw UsageError("--box and --rotation are for sources; a world's field covers its content");
  if (s.backend != "cpu")
    throw UsageError("--backend " + s.backend +
                     ": the flow around a world's solids comes from its nearest-site field on the "
                     "CPU; --backend is for sources");
  const double reach = s.reach.value_or(8.0);
  const VectorStorage storage = parse_vector_storage(s.storage);
  set_activity("loading " + s.sources);
  const LoadedWorld in = load_world(s.sources, LoadOptions{});
  const Box3i content = in.world.voxels.content_bounds();
  if (content.empty()) throw InvalidArgument(s.sources + ": the world has no solid voxel");
  const Box3i box = content.grown(static_cast<std::int32_t>(std::ceil(reach)));
  const Vec3i n = box.size();
  if (kind == OutKind::kFga && (n.x > 128 || n.y > 128 || n.z > 128))
    throw InvalidArgument("-o " + s.out + ": the field of " + s.sources + " is " + to_string(n) +
                          " voxels; an .fga holds at most 128 per axis");
  set_activity("computing the vector field of " + s.sources);
  const auto start = std::chrono::steady_clock::now();
  const WorldVectorField field(in.world, box, reach, storage);
  const double ms = ms_since(start);
  set_activity("writing " + s.out);
  const VectorVolume& volume = field.volume();
  switch (kind) {
    case OutKind::kNpy:
      outputs.stage(s.out, encode_npy(vector_npy(field.texture())));
      break;
    case OutKind::kFga:
      outputs.stage(s.out, std::string_view(encode_fga(volume, field.texture())));
      break;
    case OutKind::kVf:
      outputs.stage(s.out, encode_vf(volume, field.texture()));
      break;
    case OutKind::kVdb:
      outputs.stage(s.out, encode_vdb_world_vectors(box, field.texture(), in.world.frame));
      break;
    case OutKind::kPng: {
      VectorViewOptions view;
      view.width = s.width;
      view.height = s.height;
      outputs.stage(s.out, encode_png(render_vectors(volume, field.texture(), view)));
      break;
    }
  }
  if (!s.stats.empty()) {
    nlohmann::json j;
    j["world"] = s.sources;
    j["output"] = s.out;
    j["reach"] = reach;
    j["storage"] = vector_storage_name(storage);
    j["box"] = {{"min", {box.begin.x, box.begin.y, box.begin.z}},
                {"max_exclusive", {box.end.x, box.end.y, box.end.z}}};
    j["voxels_written"] = box.volume();
    j["ms"] = ms;
    outputs.stage_json(s.stats, j);
  }
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (flow around the solids of " << s.sources << ", "
            << to_string(n) << ", reach " << reach << ", " << std::lround(ms) << " ms)\n";
  return 0;
}

int run_vectors(const VectorSettings& s) {
  const OutKind kind = out_kind(s.out);
  if (std::filesystem::path(s.sources).extension() != ".json") {
    Outputs outputs({s.sources});
    outputs.expect(s.out, "-o");
    outputs.expect(s.stats, "--stats");
    return run_world_vectors(s, kind, outputs);
  }
  if (s.reach) throw UsageError("--reach is for a world input (.vox, .npy, .vfw), not sources");
  if (s.resolution.size() != 3) throw UsageError("--resolution takes three values: nx,ny,nz");
  if (!s.box.empty() && s.box.size() != 6)
    throw UsageError("--box takes six values: cx,cy,cz,sx,sy,sz");
  if (!s.rotation.empty() && s.rotation.size() != 4)
    throw UsageError("--rotation takes four values: degrees,ax,ay,az");
  VectorOptions options;
  options.algorithm = parse_vector_algorithm(s.algorithm);
  options.rule = parse_vector_rule(s.rule);
  const VectorStorage storage = parse_vector_storage(s.storage);
  Outputs outputs({s.sources});
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");

  set_activity("reading " + s.sources);
  const VectorSourceFrames frames = read_vector_sources(s.sources);
  const Vec3i resolution{s.resolution[0], s.resolution[1], s.resolution[2]};
  VectorVolume volume;
  if (s.box.empty()) {
    volume = volume_around(frames, resolution);
  } else {
    volume.centre = {s.box[0], s.box[1], s.box[2]};
    volume.size = {s.box[3], s.box[4], s.box[5]};
    volume.resolution = resolution;
  }
  if (!s.rotation.empty())
    volume.rotation =
        VectorVolume::rotation_about(s.rotation[0], {s.rotation[1], s.rotation[2], s.rotation[3]});
  try {
    volume.validate();
  } catch (const InvalidArgument& e) {
    throw UsageError(e.what());
  }
  if (kind == OutKind::kFga && (resolution.x > 128 || resolution.y > 128 || resolution.z > 128))
    throw UsageError("-o " + s.out +
                     ": an .fga vector field holds at most 128 voxels per axis "
                     "(Unreal's importer refuses more); lower --resolution");

  set_activity("computing the vector field of " + s.sources);
  const auto gpu_context = choose_vector_backend(s.backend);
  const auto start = std::chrono::steady_clock::now();
  VectorPassTimes totals;
  VectorTexture texture;
  gpu::VectorGpuStats gpu_totals;
  std::vector<gpu::PassTiming> gpu_passes;
  auto add_gpu = [&](const gpu::VectorGpuStats& st, const std::vector<gpu::PassTiming>& timings) {
    gpu_totals.flood_passes += st.flood_passes;
    for (const gpu::PassTiming& t : timings) {
      auto same = std::find_if(gpu_passes.begin(), gpu_passes.end(),
                               [&](const gpu::PassTiming& p) { return p.pass == t.pass; });
      if (same == gpu_passes.end())
        gpu_passes.push_back(t);
      else
        same->ms += t.ms;
    }
  };
  if (gpu_context) gpu_context->reset_counters();
  std::optional<gpu::VectorSimulation> gpu_sim;
  if (gpu_context && frames.animated) {
    gpu_sim.emplace(gpu_context, volume, storage, options, s.decay_per_s);
    for (const auto& frame : frames.frames) {
      gpu_sim->step(frame, s.dt_s);
      add_gpu(gpu_sim->last_stats(), gpu_sim->last_timings());
    }
    texture = gpu_sim->field();
  } else if (gpu_context) {
    gpu::VectorGpuStats st;
    std::vector<gpu::PassTiming> timings;
    texture = gpu::generate_vectors(*gpu_context, volume, frames.frames.front(), storage, options,
                                    nullptr, &st, &timings);
    add_gpu(st, timings);
  } else if (frames.animated) {
    VectorSimulation sim(volume, storage, options, s.decay_per_s);
    for (const auto& frame : frames.frames) {
      sim.step(frame, s.dt_s);
      const VectorPassTimes& t = sim.last_times();
      totals.seed_ms += t.seed_ms;
      totals.flood_ms += t.flood_ms;
      totals.search_ms += t.search_ms;
      totals.convert_ms += t.convert_ms;
      totals.blend_ms += t.blend_ms;
      totals.flood_passes += t.flood_passes;
    }
    texture = sim.field();
  } else {
    texture = generate_vectors(volume, frames.frames.front(), storage, options, &totals);
  }
  const double ms = ms_since(start);

  set_activity("writing " + s.out);
  switch (kind) {
    case OutKind::kNpy:
      outputs.stage(s.out, encode_npy(vector_npy(texture)));
      break;
    case OutKind::kFga:
      outputs.stage(s.out, std::string_view(encode_fga(volume, texture)));
      break;
    case OutKind::kVf:
      outputs.stage(s.out, encode_vf(volume, texture));
      break;
    case OutKind::kVdb:
      outputs.stage(s.out, encode_vdb_vectors(volume, texture));
      break;
    case OutKind::kPng: {
      VectorViewOptions view;
      view.width = s.width;
      view.height = s.height;
      outputs.stage(
          s.out, encode_png(gpu_sim       ? gpu_sim->render(view)
                            : gpu_context ? gpu::render_vectors(*gpu_context, volume, texture, view)
                                          : render_vectors(volume, texture, view)));
      break;
    }
  }
  if (!s.stats.empty()) {
    nlohmann::json j;
    j["sources_file"] = s.sources;
    j["backend"] = gpu_context ? "vulkan" : "cpu";
    j["output"] = s.out;
    j["algorithm"] = vector_algorithm_name(options.algorithm);
    j["rule"] = vector_rule_name(options.rule);
    j["storage"] = vector_storage_name(storage);
    j["frames"] = frames.frames.size();
    j["resolution"] = {resolution.x, resolution.y, resolution.z};
    j["box"] = {{"centre", {volume.centre.x, volume.centre.y, volume.centre.z}},
                {"size", {volume.size.x, volume.size.y, volume.size.z}}};
    j["voxels_written"] = volume.voxel_count() * static_cast<std::int64_t>(frames.frames.size());
    j["ms"] = ms;
    if (gpu_context) {
      // Timestamps of the device's passes (on a software device such as lavapipe they time its
      // CPU emulation, not a GPU) and the hardware-independent counters.
      j["device"] = gpu_context->device().name;
      nlohmann::json passes = nlohmann::json::object();
      for (const gpu::PassTiming& t : gpu_passes) passes[t.pass] = t.ms;
      j["gpu_passes_ms"] = passes;
      // The traffic of the field, its read-back and its picture (the error measurement below,
      // which generates the last frame again, is not counted).
      const gpu::Counters c = gpu_context->counters();
      j["gpu"] = {{"dispatches", c.dispatches},         {"submits", c.submits},
                  {"fence_waits", c.fence_waits},       {"pipeline_barriers", c.pipeline_barriers},
                  {"bytes_uploaded", c.bytes_uploaded}, {"bytes_downloaded", c.bytes_downloaded}};
      if (gpu_totals.flood_passes) j["flood_passes"] = gpu_totals.flood_passes;
    } else {
      j["passes_ms"] = {{"seed", totals.seed_ms},
                        {"flood", totals.flood_ms},
                        {"search", totals.search_ms},
                        {"convert", totals.convert_ms},
                        {"decay_blend", totals.blend_ms}};
      if (totals.flood_passes) j["flood_passes"] = totals.flood_passes;
    }
    if (options.algorithm != VectorAlgorithm::kBrute &&
        options.algorithm != VectorAlgorithm::kSplat) {
      // The last frame's winners against the exact ones (splat), as docs/vectors.md defines.
      const auto& last = frames.frames.back();
      VectorOptions exact = options;
      exact.algorithm = VectorAlgorithm::kSplat;
      std::vector<std::int32_t> approximate;
      if (gpu_context)
        gpu::generate_vectors(*gpu_context, volume, last, storage, options, &approximate);
      else
        approximate = vector_winners(volume, last, options);
      const VectorError e =
          compare_vector_winners(volume, last, vector_winners(volume, last, exact), approximate);
      j["error"] = {{"percent_source_differs", e.percent_differs()},
                    {"voxels_source_differs", e.source_differs},
                    {"max_angle_deg", e.max_angle_deg},
                    {"max_strength_error", e.max_strength_error}};
    }
    outputs.stage_json(s.stats, j);
  }
  outputs.commit();
  std::cerr << "voxfield: wrote " << s.out << " (" << to_string(resolution) << ", "
            << frames.frames.size() << (frames.frames.size() == 1 ? " frame, " : " frames, ")
            << vector_algorithm_name(options.algorithm) << ", " << vector_storage_name(storage)
            << (gpu_context ? ", vulkan, " : ", ") << std::lround(ms) << " ms)\n";
  return 0;
}

}  // namespace

void add_vectors(CLI::App& app, Action& action) {
  auto s = std::make_shared<VectorSettings>();
  CLI::App* cmd = app.add_subcommand(
      "vectors",
      "A vector-field volume texture from moving sources (direction away from the strongest "
      "source, strength 1 - d/r), one generation or one decayed and blended step per frame");
  cmd->add_option("SOURCES", s->sources,
                  "JSON: {\"sources\": [{\"position\": [x,y,z], \"previous\": [x,y,z], "
                  "\"radius\": r}, ...]} or {\"frames\": [{\"sources\": [...]}, ...]}; or a "
                  "world (.vox, .npy, .vfw): the flow away from its solid voxels")
      ->required();
  cmd->add_option("--reach", s->reach,
                  "a world input: how far its solids push, in voxels (default 8; strength "
                  "1 - d/reach from the exact distance d)")
      ->check(CLI::Range(1e-3, 16000.0));
  cmd->add_option("-o,--output", s->out,
                  ".npy (float32 a[i,j,k,4]: direction, strength), .fga (Unreal), .vf (Unity VFX "
                  "Graph), .vdb (OpenVDB grids 'vectors' and 'strength') or .png (the "
                  "visualiser); written atomically")
      ->required();
  cmd->add_option("--resolution", s->resolution, "voxels per axis: nx,ny,nz (default 64,64,64)")
      ->delimiter(',')
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--box", s->box,
                  "the volume: centre and full size, cx,cy,cz,sx,sy,sz (default: around the "
                  "sources)")
      ->delimiter(',')
      ->check(CLI::Number);
  cmd->add_option("--rotation", s->rotation, "the volume's rotation: degrees,ax,ay,az")
      ->delimiter(',')
      ->check(CLI::Number);
  cmd->add_option("--algorithm", s->algorithm, "splat (default, exact), brute, jfa, jfa+1, jfa+2")
      ->check(CLI::IsMember({"splat", "brute", "jfa", "jfa+1", "jfa+2"}));
  cmd->add_option("--rule", s->rule,
                  "strongest (default: greatest 1 - d/r) or nearest (the paper's text rule)")
      ->check(CLI::IsMember({"strongest", "nearest"}));
  cmd->add_option("--storage", s->storage, "rgba8 (default), rgba16f or rgba32f")
      ->check(CLI::IsMember({"rgba8", "rgba16f", "rgba32f"}));
  cmd->add_option("--dt", s->dt_s, "seconds per frame step (default 1/60)")
      ->check(finite_positive());
  cmd->add_option("--decay-per-s", s->decay_per_s,
                  "strength lost per second by the previous field (default 1)")
      ->check(finite_non_negative());
  cmd->add_option("--width", s->width, "picture width (.png)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", s->height, "picture height (.png)")->check(CLI::Range(1, 16384));
  cmd->add_option("--backend", s->backend,
                  "cpu (default), vulkan (any Vulkan device, software included) or auto (a "
                  "hardware GPU if there is one, else the CPU): where the passes run; the same "
                  "texels either way")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->add_option("--stats", s->stats, "write pass timings (and jfa's error) as JSON");
  cmd->callback([s, &action] { action = [s] { return run_vectors(*s); }; });
}

}  // namespace voxfield::cli
