// voxfield benchmark: exact distance fields on the generated scenes and the real corpus.
//
// Every line reports the median, min and max of N timed runs after a warm-up, the throughput,
// the threads used, and the memory the transform needed beyond its input and its output (peak
// resident set during the run, minus the resident set before it, minus the output's own bytes).
// Output: a table on stdout and, with --json, one record per line for bench/report.py.
#include <malloc.h>
#include <CLI/CLI.hpp>

#include <iostream>
#include <nlohmann/json.hpp>

#include "bench_util.h"
#include "voxfield/chunk_memory.h"
#include "voxfield/distance.h"
#include "voxfield/hash.h"
#include "voxfield/npy.h"
#include "voxfield/parallel.h"
#include "voxfield/scene.h"
#include "voxfield/vox.h"

using namespace voxfield;

int main(int argc, char** argv) {
  CLI::App app{"voxfield field benchmark"};
  std::vector<std::string> scenes{"spheres", "terrain"};
  std::vector<int> sizes{128, 256};
  std::vector<std::string> metrics{"manhattan", "chebyshev", "euclidean"};
  std::vector<int> threads{1, 2};
  std::vector<std::string> files;
  std::string storage = "f32", json_path;
  int runs = 5;
  double clamp = 0;
  app.add_option("--scenes", scenes)->delimiter(',');
  app.add_option("--sizes", sizes)->delimiter(',');
  app.add_option("--metrics", metrics)->delimiter(',');
  app.add_option("--threads", threads)->delimiter(',');
  app.add_option("--inputs", files, ".vox or .npy files to include (named by their stem)")
      ->delimiter(',');
  app.add_option("--storage", storage,
                 "f32, u16 or u8 (a DistanceField), or dense-f64: compute_distance_field_into a "
                 "float64 array allocated once (what voxfield.ndimage does, without Python)");
  app.add_option("--max-distance", clamp);
  app.add_option("--runs", runs)->check(CLI::Range(1, 1000));
  app.add_option("--json", json_path, "append one JSON record per line");
  CLI11_PARSE(app, argc, argv);

  struct Input {
    std::string name;
    World world;
  };
  std::vector<Input> inputs;
  for (const auto& s : scenes)
    for (int n : sizes) {
      if (s.empty()) continue;
      SceneOptions o;
      o.size = Vec3i::splat(n);
      inputs.push_back({s + "-" + std::to_string(n), make_scene(s, o)});
    }
  for (const auto& f : files) {
    World loaded;
    if (std::filesystem::path(f).extension() == ".npy") {
      loaded = world_from_npy(read_npy(f), f);
    } else {
      loaded = std::move(read_vox(f).world);
    }
    // Bound the world so that the domain is the file's volume (npy) or content box (vox).
    const Box3i box = std::filesystem::path(f).extension() == ".npy"
                          ? Box3i::from_size(read_npy(f).dims)
                          : loaded.voxels.content_bounds();
    World w(32, box);
    std::vector<std::uint8_t> dense(static_cast<std::size_t>(box.volume()));
    loaded.voxels.copy_to_dense(box, dense.data());
    w.voxels.copy_from_dense(box, dense.data());
    inputs.push_back({std::filesystem::path(f).stem().string(), std::move(w)});
  }
  std::ofstream json;
  if (!json_path.empty()) json.open(json_path, std::ios::app);
  std::printf("%-26s %-10s %4s %9s %9s %9s %10s %12s  %-16s\n", "input", "metric", "thr", "median",
              "min", "max", "Mvox/s", "extra B/vox", "field hash");
  for (const auto& in : inputs) {
    const Box3i domain = *in.world.voxels.bounds();
    const double voxels = static_cast<double>(domain.volume());
    for (const auto& m : metrics)
      for (int t : threads) {
        DistanceOptions o;
        o.metric = parse_metric(m);
        o.max_distance = clamp;
        ThreadLimit limit(t);
        if (storage == "dense-f64") {
          const Vec3i n = domain.size();
          std::vector<double> dense(static_cast<std::size_t>(domain.volume()));
          const DenseDistances<double> out{dense.data(), {1, n.x, std::ptrdiff_t{n.x} * n.y}};
          const bench::Timing tm =
              bench::time_runs(runs, [&] { compute_distance_field_into(in.world.voxels, o, out); });
          // FNV-1a of the doubles, x fastest: not the field hash of the other storages.
          const std::uint64_t hash = fnv1a(kFnvOffset, dense.data(), dense.size() * sizeof(double));
          std::printf("%-26s %-10s %4d %9.1f %9.1f %9.1f %10.0f %12s  %016llx\n", in.name.c_str(),
                      m.c_str(), t, tm.median_ms, tm.min_ms, tm.max_ms,
                      voxels / (tm.median_ms * 1e3), "-", static_cast<unsigned long long>(hash));
          std::fflush(stdout);
          continue;
        }
        o.storage = parse_storage(storage);
        const bench::Timing tm =
            bench::time_runs(runs, [&] { (void)compute_distance_field(in.world, o); });
        // Memory: one more run with the peak reset, from nothing cached: the arrays the timed
        // runs freed into voxfield's cache (chunk_memory.h) go back first, so that the peak counts
        // every page this run touches.
        trim_chunk_cache();
        malloc_trim(0);  // return freed pages, so that the baseline is what is really in use
        bench::reset_peak_rss();
        const std::size_t before = bench::proc_status_bytes("VmRSS");
        const DistanceField f = compute_distance_field(in.world, o);
        const std::size_t peak = bench::proc_status_bytes("VmHWM");
        const std::size_t out_bytes =
            std::visit([](const auto& g) { return g.memory().bytes; }, f.values);
        const double extra = (static_cast<double>(peak) - static_cast<double>(before) -
                              static_cast<double>(out_bytes)) /
                             voxels;
        const std::uint64_t hash = content_hash(f);  // the result, pinned beside its time
        std::printf("%-26s %-10s %4d %9.1f %9.1f %9.1f %10.0f %12.3f  %016llx\n", in.name.c_str(),
                    m.c_str(), t, tm.median_ms, tm.min_ms, tm.max_ms, voxels / (tm.median_ms * 1e3),
                    extra, static_cast<unsigned long long>(hash));
        std::fflush(stdout);
        if (json) {
          json << nlohmann::json{{"tool", "voxfield"},  {"input", in.name},
                                 {"metric", m},         {"threads", t},
                                 {"storage", storage},  {"max_distance", clamp},
                                 {"voxels", voxels},    {"median_ms", tm.median_ms},
                                 {"min_ms", tm.min_ms}, {"max_ms", tm.max_ms},
                                 {"runs", runs},        {"extra_bytes_per_voxel", extra},
                                 {"field_hash", hash}}
                      .dump()
               << "\n";
        }
      }
  }
}
