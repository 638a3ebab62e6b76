// voxfield benchmark: CPU ray marching on a generated terrain.
//
// For each configuration, the median of N timed frames after a warm-up: milliseconds, primary
// rays per second, and the traversal counters per ray (DDA state changes, voxels read, skips).
// Configurations cover the questions: resolution (640x360, 1280x720), shading cost
// (primary + flat shading, + ambient occlusion, + soft shadows), what skipping buys (none, empty
// chunks, distance field) and which field to skip by (Manhattan, Chebyshev, Euclidean).
// A "trace only" row times the primary rays without any shading.
#include <CLI/CLI.hpp>

#include <iostream>
#include <nlohmann/json.hpp>

#include "bench_util.h"
#include "voxfield/parallel.h"
#include "voxfield/render.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

struct Config {
  std::string name;
  Metric metric = Metric::kManhattan;
  SkipMode skip = SkipMode::kDistance;
  bool ao = false, shadows = false, trace_only = false;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"voxfield render benchmark"};
  int size = 512, runs = 7, threads = 0;
  std::vector<std::string> resolutions{"640x360", "1280x720"};
  std::string json_path, only;
  app.add_option("--size", size, "terrain edge in voxels")->check(CLI::Range(16, 1024));
  app.add_option("--runs", runs)->check(CLI::Range(1, 1000));
  app.add_option("--threads", threads, "0 = all cores");
  app.add_option("--resolutions", resolutions)->delimiter(',');
  app.add_option("--only", only, "run only configurations whose name contains this");
  app.add_option("--json", json_path, "append one JSON record per line");
  CLI11_PARSE(app, argc, argv);
  std::optional<ThreadLimit> limit;
  if (threads > 0) limit.emplace(threads);

  SceneOptions so;
  so.size = Vec3i::splat(size);
  const World world = make_terrain(so);
  const Box3i box = Box3i::from_size(so.size);

  const std::vector<Config> configs = {
      {"trace only, manhattan skips", Metric::kManhattan, SkipMode::kDistance, false, false, true},
      {"primary + flat shading, manhattan skips", Metric::kManhattan, SkipMode::kDistance},
      {"primary + flat shading, empty chunks only", Metric::kManhattan, SkipMode::kChunks},
      {"primary + flat shading, plain DDA", Metric::kManhattan, SkipMode::kNone},
      {"primary + flat shading, chebyshev skips", Metric::kChebyshev, SkipMode::kDistance},
      {"primary + flat shading, euclidean skips", Metric::kEuclidean, SkipMode::kDistance},
      {"primary + AO", Metric::kManhattan, SkipMode::kDistance, true, false},
      {"primary + AO + soft shadows", Metric::kManhattan, SkipMode::kDistance, true, true},
  };
  std::optional<RenderScene> scenes[3];
  double field_ms[3] = {0, 0, 0};
  auto scene_for = [&](Metric m) -> const RenderScene& {
    const int i = static_cast<int>(m);
    if (!scenes[i]) {
      RenderSceneOptions o;
      o.skip_metric = m;
      scenes[i].emplace(world, o, box);
      field_ms[i] = scenes[i]->field_ms();
    }
    return *scenes[i];
  };

  std::cout << "terrain " << size << "^3, " << max_threads() << " threads, median of " << runs
            << " frames\n";
  std::cout << "resolution  configuration                                   ms   Mrays/s  "
               "steps/ray  reads/ray\n";
  for (const std::string& res : resolutions) {
    const auto x = res.find('x');
    const int w = std::stoi(res.substr(0, x)), h = std::stoi(res.substr(x + 1));
    for (const Config& c : configs) {
      if (!only.empty() && c.name.find(only) == std::string::npos) continue;
      const RenderScene& scene = scene_for(c.metric);
      const Camera cam = Camera::framing(world.voxels.content_bounds(), static_cast<double>(w) / h);
      RenderOptions o;
      o.width = w;
      o.height = h;
      o.skip = c.skip;
      o.ambient_occlusion = c.ao;
      o.soft_shadows = c.shadows;
      RenderStats st;
      bench::Timing t;
      std::uint64_t frame_hash = 0;  // the frame, pinned beside its time (none when tracing only)
      if (c.trace_only) {
        // The primary rays alone, no shading and no image: made and traced as one batch by
        // trace_rays, the entry point of ray casts that are not pictures.
        const auto proj = cam.projector(w, h);
        std::vector<Ray> rays(static_cast<std::size_t>(w) * h);
        std::vector<RayHit> hits(rays.size());
        t = bench::time_runs(runs, [&] {
          parallel_for(static_cast<std::size_t>(h), 4, [&](std::size_t b, std::size_t e) {
            for (std::size_t y = b; y < e; ++y)
              for (int px = 0; px < w; ++px)
                rays[y * w + px] = proj.ray(px + 0.5, static_cast<double>(y) + 0.5);
          });
          st.primary = {};
          trace_rays(scene, rays, hits, c.skip, &st.primary);
        });
      } else {
        Image frame;
        t = bench::time_runs(runs, [&] { frame = render(scene, cam, o, &st); });
        frame_hash = content_hash(frame);
      }
      const double rays = static_cast<double>(w) * h;
      const double mrays = rays / (t.median_ms * 1e3);
      std::printf("%-10s  %-42s %7.1f %8.2f %10.2f %10.2f\n", res.c_str(), c.name.c_str(),
                  t.median_ms, mrays, st.primary.steps / rays, st.primary.voxel_reads / rays);
      if (!json_path.empty()) {
        nlohmann::json j{
            {"size", size},
            {"resolution", res},
            {"config", c.name},
            {"metric", metric_name(c.metric)},
            {"skip", skip_mode_name(c.skip)},
            {"ms", t.median_ms},
            {"min_ms", t.min_ms},
            {"max_ms", t.max_ms},
            {"mrays_per_s", mrays},
            {"threads", max_threads()},
            {"steps_per_ray", st.primary.steps / rays},
            {"reads_per_ray", st.primary.voxel_reads / rays},
            {"shadow_rays", st.shadow.rays},
            {"field_ms", field_ms[static_cast<int>(c.metric)]},
            {"image_hash", frame_hash ? nlohmann::json(frame_hash) : nlohmann::json()}};
        std::ofstream(json_path, std::ios::app) << j.dump() << "\n";
      }
    }
  }
  return 0;
}
