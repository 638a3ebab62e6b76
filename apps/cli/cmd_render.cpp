// voxfield render IN -o OUT.png: a frame of a world, ray-marched on the CPU through its distance
// field, in one of four views (shaded, distance, error, chunks).
#include <algorithm>
#include <iostream>

#include "backend_choice.h"
#include "cli.h"
#include "field_args.h"
#include "progress.h"
#include "voxfield/parallel.h"
#include "voxfield/png.h"
#include "voxfield/render_executor.h"

namespace voxfield::cli {
namespace {

struct RenderSettings {
  std::string in, out, camera = "auto", view = "shaded", algorithm = "jfa", metric = "manhattan",
                       skip = "distance", stats, backend = "cpu", fields = "auto";
  int width = 1280, height = 720, chunk_edge = 32, threads = 0, repeat = 1;
  bool no_shadows = false, no_ao = false;
  double fog = 0;
  std::optional<int> slice;
  std::string grid;
  std::string camera_frame = "voxels";
};

int run_render(const RenderSettings& s) {
  check_grid_input(s.in, s.grid);
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  Outputs outputs({s.in});
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");
  set_activity("loading " + s.in);
  LoadOptions lo;
  lo.chunk_edge = s.chunk_edge;
  lo.vdb_grid = s.grid;
  const LoadedWorld in = load_world(s.in, lo);
  set_activity("rendering " + s.in);
  if (in.extent.empty()) throw InvalidArgument(s.in + ": the input holds no volume");

  RenderSceneOptions so;
  so.skip_metric = parse_metric(s.metric);
  so.lighting_field = !(s.no_shadows && s.no_ao);
  RenderOptions o;
  o.width = s.width;
  o.height = s.height;
  o.view = parse_render_view(s.view);
  o.skip = parse_skip_mode(s.skip);
  o.soft_shadows = !s.no_shadows;
  o.ambient_occlusion = !s.no_ao;
  o.fog_density = s.fog;
  o.slice_z = s.slice;
  o.error_algorithm = parse_algorithm(s.algorithm);
  const double aspect = static_cast<double>(s.width) / s.height;
  // Automatic cameras frame what is there: the content, within the file's extent.
  const Box3i content = in.world.voxels.content_bounds().intersect(in.extent);
  const Camera camera =
      Camera::parse(s.camera, s.camera == "top" || content.empty() ? in.extent : content, aspect,
                    s.camera_frame == "world" ? &in.world.frame : nullptr);

  // With --repeat, the frame is rendered several times and the median time reported (the
  // image is the same every time: rendering is deterministic).
  const Executor executor = choose_executor(s.backend);
  if (s.fields == "device" && !executor.on_gpu())
    throw InvalidArgument("--fields device needs a Vulkan device (--backend vulkan)");
  // Fields computed where the frame is drawn on a hardware GPU; on a CPU device (lavapipe) the
  // host computes them faster (docs/benchmarks.md), unless asked.
  std::optional<RenderScene> host_scene;
  std::optional<gpu::DeviceRenderScene> device_scene;
  if (executor.on_gpu() &&
      (s.fields == "device" || (s.fields == "auto" && executor.device()->device().hardware))) {
    // What the device cannot hold (a box beyond its storage-buffer range or its memory) the host
    // computes, unless the device was asked for.
    const auto on_the_host = [&](const Error& e) {
      std::cerr << "voxfield: the fields on the host: " << e.what() << "\n";
    };
    try {
      device_scene.emplace(executor.shared_device(), in.world, so, in.extent);
    } catch (const InvalidArgument& e) {
      if (s.fields == "device") throw InvalidArgument(s.in + ": " + e.what());
      on_the_host(e);
    } catch (const GpuOutOfMemory& e) {
      if (s.fields == "device") throw;
      on_the_host(e);
    }
  }
  const bool device_fields = device_scene.has_value();
  if (!device_scene) host_scene.emplace(in.world, so, in.extent);
  const double field_ms =
      device_scene ? device_scene->build_stats().field_ms : host_scene->field_ms();
  RenderStats st;
  Image image;
  std::vector<double> times;
  std::vector<gpu::PassTiming> pass_timings;
  for (int r = 0; r < s.repeat; ++r) {
    image = device_scene ? device_scene->render(camera, o, &st, &pass_timings)
                         : render(executor, *host_scene, camera, o, &st, progress(), &pass_timings);
    times.push_back(st.ms);
  }
  std::sort(times.begin(), times.end());
  st.ms = times[times.size() / 2];
  outputs.stage(s.out, encode_png(image));
  // The status goes to stderr when the frame itself goes to standard output.
  std::ostream& status = s.out == "-" ? std::cerr : std::cout;
  status << "voxfield render: " << s.out << " (" << s.width << "x" << s.height << ", " << s.view
         << " view), " << st.ms << " ms, " << st.rays_per_second() / 1e6
         << " M primary rays/s, fields " << field_ms << " ms"
         << (device_fields ? " (on the device)" : "") << "\n";
  if (o.view == RenderView::kError)
    status << "  " << s.algorithm << ": " << st.rays_through_geometry
           << " rays skip through geometry, largest error on a ray " << st.max_error << " voxels\n";
  if (!s.stats.empty()) {
    auto counters = [](const TraversalCounters& c) {
      return nlohmann::json{{"rays", c.rays},
                            {"steps", c.steps},
                            {"voxel_reads", c.voxel_reads},
                            {"chunk_skips", c.chunk_skips},
                            {"distance_skips", c.distance_skips}};
    };
    nlohmann::json j{{"input", s.in},
                     {"ms", st.ms},
                     {"image_hash", hash_hex(content_hash(image))},
                     {"width", st.width},
                     {"height", st.height},
                     {"view", s.view},
                     {"skip", s.skip},
                     {"skip_metric", s.metric},
                     {"threads", max_threads()},
                     {"backend", backend_name(executor.backend())},
                     {"field_ms", field_ms},
                     {"fields", device_fields ? "device" : "host"},
                     {"primary_rays_per_second", st.rays_per_second()},
                     {"primary", counters(st.primary)},
                     {"shadow", counters(st.shadow)}};
    if (executor.on_gpu()) {
      j["gpu"] = gpu_json(executor);
      j["gpu"]["passes"] = pass_timings_json(pass_timings);
    }
    if (device_scene) {
      const gpu::DeviceRenderScene::UpdateStats& b = device_scene->build_stats();
      j["device_fields"] = {{"field_ms", b.field_ms},
                            {"scene_ms", b.scene_ms},
                            {"chunks_packed", b.chunks_repacked},
                            {"bytes_up", b.bytes_up},
                            {"bytes_down", b.bytes_down},
                            {"submits", b.submits}};
    }
    if (o.view == RenderView::kError) {
      j["algorithm"] = s.algorithm;
      j["rays_through_geometry"] = st.rays_through_geometry;
      j["max_error"] = st.max_error;
    }
    outputs.stage_json(s.stats, j);
  }
  outputs.commit();
  return 0;
}

}  // namespace

void add_render(CLI::App& app, Action& action) {
  auto s = std::make_shared<RenderSettings>();
  CLI::App* cmd =
      app.add_subcommand("render", "Ray-march a frame of a world on the CPU and write a PNG");
  cmd->add_option("IN", s->in, "input .vox, .npy, .vfw or .vdb")->required();
  add_grid_option(cmd, s->grid);
  cmd->add_option("-o,--output", s->out, "output .png")->required();
  cmd->add_option("--width", s->width, "image width in pixels")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", s->height, "image height in pixels")->check(CLI::Range(1, 16384));
  cmd->add_option("--camera", s->camera,
                  "auto | top | eye=x,y,z:target=x,y,z[:up=x,y,z][:fov=deg][:ortho=height] (z up; "
                  "voxel units, or the world's with --camera-frame world)")
      ->check(camera_spec());
  cmd->add_option(
         "--camera-frame", s->camera_frame,
         "voxels (default) or world: an eye=...:target=... camera in the world's frame "
         "(a .vfw's origin, voxel size and rotation, of any voxel shape); auto and top frame "
         "the content either way")
      ->check(CLI::IsMember({"voxels", "world"}));
  cmd->add_option("--view", s->view, "shaded | distance | error | chunks")
      ->check(CLI::IsMember({"shaded", "distance", "error", "chunks"}));
  cmd->add_option("--algorithm", s->algorithm,
                  "error view: the approximation shown against the exact field")
      ->check(CLI::IsMember(algorithm_names()));
  cmd->add_option("--metric", s->metric,
                  "field rays skip by: manhattan (default), chebyshev, euclidean")
      ->check(CLI::IsMember({"manhattan", "chebyshev", "euclidean"}));
  cmd->add_option("--backend", s->backend,
                  "cpu (default), vulkan or auto; the GPU draws the shaded and chunks views")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->add_option("--fields", s->fields,
                  "with --backend vulkan: where the skip and lighting fields are computed — "
                  "device (they never leave it), host, or auto (default: the device when it is a "
                  "hardware GPU, the host on a CPU device such as lavapipe)")
      ->check(CLI::IsMember({"auto", "host", "device"}));
  cmd->add_option("--skip", s->skip, "none (plain DDA), chunks, distance (default)")
      ->check(CLI::IsMember({"none", "chunks", "distance"}));
  cmd->add_option("--slice", s->slice, "distance view: z of the cut plane (default: the middle)");
  cmd->add_flag("--no-shadows", s->no_shadows, "no soft shadows");
  cmd->add_flag("--no-ao", s->no_ao, "no ambient occlusion");
  cmd->add_option("--fog", s->fog, "fog density per voxel of travel (e.g. 0.002)")
      ->check(finite_non_negative());
  cmd->add_option("--chunk", s->chunk_edge, "chunk edge: 8, 16, 32, 64 or 128")
      ->check(CLI::IsMember({8, 16, 32, 64, 128}));
  cmd->add_option("--threads", s->threads, "threads, 1..1024 (default: all cores)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--repeat", s->repeat, "render N times, report the median time")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--stats", s->stats, "write timings and traversal counters as JSON");
  cmd->callback([s, &action] { action = [s] { return run_render(*s); }; });
}

}  // namespace voxfield::cli
