// voxfield bench edits: the reference dissertation's automated test — a seeded stream of random
// sphere edits with random materials (air included, so some edits delete), each followed by an
// incremental exact update — with latency statistics, work done and memory.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <numeric>
#include <random>
#include <sstream>

#include "backend_choice.h"
#include "cli.h"
#include "field_args.h"
#include "voxfield/distance_executor.h"
#include "voxfield/edit_stream.h"
#include "voxfield/parallel.h"
#include "voxfield/scene.h"

namespace voxfield::cli {
namespace {

struct BenchEditsSettings {
  int world = 256;
  int edits = 1000;
  double interval_ms = 200;
  std::uint64_t seed = 6683787;
  int radius_min = 1;
  int radius_max = 0;  // 0: chunk edge - 1
  std::string scene = "terrain";
  bool verify = false;
  std::string csv, json, backend = "cpu";
  FieldArgs field;
};

struct TimeSummary {
  double mean, median, stddev, ci95, p99, max;
};

TimeSummary summarise(std::vector<double> v) {
  TimeSummary s{};
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  const double n = static_cast<double>(v.size());
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
  s.median = v[v.size() / 2];
  double ss = 0;
  for (double x : v) ss += (x - s.mean) * (x - s.mean);
  s.stddev = v.size() > 1 ? std::sqrt(ss / (n - 1)) : 0;
  s.ci95 = 1.96 * s.stddev / std::sqrt(n);  // half-width of the 95% confidence interval of the mean
  s.p99 = v[std::min(v.size() - 1, static_cast<std::size_t>(0.99 * (n - 1) + 0.5))];
  s.max = v.back();
  return s;
}

int run_bench_edits(const BenchEditsSettings& s) {
  std::optional<ThreadLimit> limit;
  if (s.field.threads > 0) limit.emplace(s.field.threads);
  const int radius_max = s.radius_max > 0 ? s.radius_max : s.field.chunk_edge - 1;
  if (s.radius_min < 0 || radius_max < s.radius_min)
    throw UsageError("need 0 <= --radius-min <= --radius-max");
  Outputs outputs;
  outputs.expect(s.csv, "--csv");
  outputs.expect(s.json, "--json");
  SceneOptions so;
  so.size = Vec3i::splat(s.world);
  so.seed = s.seed;
  so.chunk_edge = s.field.chunk_edge;
  auto t0 = std::chrono::steady_clock::now();
  World world = make_scene(s.scene, so);
  const double generate_ms = ms_since(t0);
  const DistanceOptions o = s.field.options();
  t0 = std::chrono::steady_clock::now();
  IncrementalDistanceField field(choose_executor(s.backend), world, o);
  const double build_ms = ms_since(t0);
  const gpu::Counters gpu_before = gpu_counters(field.executor());

  // The dissertation's stream: seeded positions anywhere in the world, radii in [min, max],
  // materials 0..255 where 0 (air) deletes.
  RandomEditStream stream(Box3i::from_size(Vec3i::splat(s.world)), s.seed, s.radius_min,
                          radius_max);
  DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy);
  std::vector<double> latency_ms, update_ms;
  std::vector<std::int64_t> recomputed;
  std::int64_t mismatches = 0;
  // Rows are kept in memory and written with the other outputs at the end (all or nothing).
  std::ostringstream csv;
  const bool want_csv = !s.csv.empty();
  if (want_csv)
    csv << "edit,time_s,radius,material,voxels_changed,voxels_recomputed,edit_ms,update_ms,latency_"
           "ms\n";
  for (int i = 0; i < s.edits; ++i) {
    const Edit e = stream.next();
    const int radius = static_cast<int>(std::get<SphereBrush>(e.brush).radius);
    const int material = e.op == EditOp::kCarve ? 0 : e.material;
    const auto a = std::chrono::steady_clock::now();
    const EditResult r = apply_edit(world, e, &dirty);
    const auto b = std::chrono::steady_clock::now();
    const auto st = field.update(dirty);
    const auto c = std::chrono::steady_clock::now();
    dirty.clear();
    const double em = std::chrono::duration<double, std::milli>(b - a).count();
    const double um = std::chrono::duration<double, std::milli>(c - b).count();
    latency_ms.push_back(em + um);
    update_ms.push_back(um);
    recomputed.push_back(st.voxels_recomputed);
    if (want_csv) {
      csv << i << "," << i * s.interval_ms / 1000.0 << "," << radius << "," << material << ","
          << r.voxels_changed << "," << st.voxels_recomputed << "," << em << "," << um << ","
          << em + um << "\n";
    }
    if (s.verify) {
      // Compare the whole field with a full rebuild, bit for bit.
      const DistanceField full = compute_distance_field(world, field.options());
      const Box3i box = field.field().domain;
      std::visit(
          [&](const auto& g) {
            using G = std::decay_t<decltype(g)>;
            std::vector<typename G::value_type> x(static_cast<std::size_t>(box.volume())),
                y(x.size());
            g.copy_to_dense(box, x.data());
            std::get<G>(full.values).copy_to_dense(box, y.data());
            mismatches += std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) != 0;
          },
          field.field().values);
    }
  }
  const gpu::Counters gpu_after = gpu_counters(field.executor());
  const TimeSummary lat = summarise(latency_ms), upd = summarise(update_ms);
  const std::size_t field_bytes = field.memory_bytes();
  const std::size_t world_bytes = world.voxels.memory().bytes;
  const double voxels = std::pow(static_cast<double>(s.world), 3);
  const double within =
      static_cast<double>(std::count_if(latency_ms.begin(), latency_ms.end(),
                                        [&](double x) { return x <= s.interval_ms; })) /
      std::max<double>(1, static_cast<double>(latency_ms.size()));
  std::cout << std::fixed << std::setprecision(3) << "voxfield bench edits: " << s.scene << " "
            << s.world << "^3, chunk " << s.field.chunk_edge << ", " << s.edits
            << " sphere edits r " << s.radius_min << ".." << radius_max << ", seed " << s.seed
            << ", " << metric_name(o.metric) << (o.signed_distance ? " signed" : "") << " clamp "
            << o.max_distance << " " << storage_name(o.storage) << ", " << max_threads()
            << " threads\n"
            << "  build " << build_ms << " ms; per edit (edit + update) ms: mean " << lat.mean
            << " +- " << lat.ci95 << " (95% CI), median " << lat.median << ", std " << lat.stddev
            << ", p99 " << lat.p99 << ", max " << lat.max << "\n  update only: median "
            << upd.median << ", p99 " << upd.p99 << "; voxels recomputed per edit: mean "
            << std::accumulate(recomputed.begin(), recomputed.end(), 0.0) / std::max(1, s.edits)
            << "\n  memory: world " << world_bytes / voxels << " + field " << field_bytes / voxels
            << " bytes/voxel; " << 100.0 * within << "% of updates within the " << s.interval_ms
            << " ms interval\n";
  if (s.verify)
    std::cout << "  verify: " << mismatches << " of " << s.edits
              << " updates differ from a full rebuild\n";
  nlohmann::json gpu_stats = nullptr;
  if (field.on_gpu()) {
    // Per update, hardware-independent: what the dissertation's design spent a fence on per pass.
    const double n = std::max(1, s.edits);
    gpu_stats = gpu_json(field.executor());
    gpu_stats["per_update"] = {
        {"submits", (gpu_after.submits - gpu_before.submits) / n},
        {"fence_waits", (gpu_after.fence_waits - gpu_before.fence_waits) / n},
        {"dispatches", (gpu_after.dispatches - gpu_before.dispatches) / n},
        {"bytes_uploaded", (gpu_after.bytes_uploaded - gpu_before.bytes_uploaded) / n},
        {"bytes_downloaded_outside_verify",
         s.verify
             ? nlohmann::json(nullptr)
             : nlohmann::json((gpu_after.bytes_downloaded - gpu_before.bytes_downloaded) / n)}};
    std::cout << "  gpu (" << gpu_stats["device"].get<std::string>() << "): per update "
              << gpu_stats["per_update"].dump() << "\n";
  }
  if (!s.json.empty()) {
    auto summary_json = [](const TimeSummary& x) {
      return nlohmann::json{{"mean", x.mean}, {"median", x.median}, {"std", x.stddev},
                            {"ci95", x.ci95}, {"p99", x.p99},       {"max", x.max}};
    };
    outputs.stage_json(
        s.json,
        {{"scene", s.scene},
         {"world", s.world},
         {"chunk", s.field.chunk_edge},
         {"edits", s.edits},
         {"seed", s.seed},
         {"radius_min", s.radius_min},
         {"radius_max", radius_max},
         {"metric", metric_name(o.metric)},
         {"signed", o.signed_distance},
         {"max_distance", o.max_distance},
         {"storage", storage_name(o.storage)},
         {"threads", max_threads()},
         {"generate_ms", generate_ms},
         {"build_ms", build_ms},
         {"latency_ms", summary_json(lat)},
         {"update_ms", summary_json(upd)},
         {"mean_voxels_recomputed",
          std::accumulate(recomputed.begin(), recomputed.end(), 0.0) / std::max(1, s.edits)},
         {"world_bytes_per_voxel", world_bytes / voxels},
         {"field_bytes_per_voxel", field_bytes / voxels},
         {"within_interval", within},
         {"field_hash", hash_hex(content_hash(field.field()))},  // after the last edit
         {"backend", field.on_gpu() ? "vulkan" : "cpu"},
         {"gpu", gpu_stats},
         {"verify_mismatches", s.verify ? nlohmann::json(mismatches) : nlohmann::json(nullptr)}});
  }
  if (want_csv) outputs.stage(s.csv, std::string_view(csv.str()));
  outputs.commit();
  return s.verify && mismatches > 0 ? 1 : 0;
}

}  // namespace

void add_bench(CLI::App& app, Action& action) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks");
  bench->require_subcommand(1);
  auto s = std::make_shared<BenchEditsSettings>();
  s->field.max_distance = 16;
  CLI::App* cmd = bench->add_subcommand(
      "edits", "The dissertation's stream of random sphere edits with incremental updates");
  cmd->add_option("--world", s->world, "world edge in voxels")->check(CLI::Range(8, 4096));
  cmd->add_option("--scene", s->scene, "terrain or spheres")
      ->check(CLI::IsMember({"terrain", "spheres"}));
  cmd->add_option("--edits", s->edits, "number of edits")->check(CLI::Range(1, 10000000));
  cmd->add_option("--interval-ms", s->interval_ms,
                  "time between edits in the stream (reported against)")
      ->check(finite_non_negative());
  cmd->add_option("--seed", s->seed, "random seed");
  cmd->add_option("--radius-min", s->radius_min, "smallest sphere radius");
  cmd->add_option("--radius-max", s->radius_max, "largest sphere radius (default: chunk edge - 1)");
  s->field.add_to(cmd);
  cmd->add_option("--backend", s->backend, "cpu (default), vulkan or auto")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->add_flag("--verify", s->verify,
                "compare the field with a full rebuild after every edit (exit 1 on a mismatch)");
  cmd->add_option("--csv", s->csv, "one row per edit");
  cmd->add_option("--json", s->json, "summary as JSON");
  cmd->callback([s, &action] { action = [s] { return run_bench_edits(*s); }; });
  add_bench_vectors(bench, action);
}

}  // namespace voxfield::cli
