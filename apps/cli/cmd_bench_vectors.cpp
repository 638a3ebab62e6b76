// voxfield bench vectors --test NAME: the six tests of Hamlin's benchmark program ("Volumetric
// Interaction", section 4), done with the error columns the paper lacked and whole-step times
// (generation, conversion, decay and blend — not CPU dispatch time). docs/vectors.md describes the
// agents' seeded motion and each test's sweep; docs/benchmarks.md holds the figures.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>

#include "chart.h"
#include "cli.h"
#include "vector_backend.h"
#include "voxfield/gpu_vectors.h"
#include "voxfield/parallel.h"
#include "voxfield/vector_agents.h"
#include "voxfield/vectors.h"

namespace voxfield::cli {
namespace {

struct BenchVectorSettings {
  std::string test = "fidelity", csv, plot, storage = "rgba8", backend = "cpu";
  std::vector<std::string> algorithms;  // only these (default: each test's own)
  int steps = 60, threads = 0;
  std::uint32_t seed = 1;
};

struct Row {
  std::string test, algorithm;
  Vec3i resolution;
  int sources = 0;
  double dt = 0, decay = 0;
  double generate_ms = 0, blend_ms = 0, step_ms = 0, p99_step_ms = 0;
  double percent_differs = 0, max_angle_deg = 0, max_strength_error = 0;
  double mean_strength = 0;
  double dispatches_per_step = 0;  // the Vulkan backend's counters (0 on the CPU)
  double submits_per_step = 0;
};

// Runs `steps` whole steps (generation, conversion, decay and blend) of `count` agents and, for
// the approximate algorithms, measures each step's winners against splatting's.
// On the Vulkan backend a step is one submission: its time is the wall clock from recording to
// the fence (lavapipe: CPU emulation), the generation's the device's timestamps of its passes (the
// step's generation, decay and blend are one dispatch there, so decay_blend_ms stays 0).
Row run_case(const std::string& test, VectorAlgorithm algorithm, Vec3i resolution, int count,
             double dt, double decay, VectorStorage storage, int steps, std::uint32_t seed,
             const std::shared_ptr<gpu::Context>& gpu_context) {
  const VectorVolume volume = vector_agents_volume(resolution);
  VectorOptions options;
  options.algorithm = algorithm;
  std::optional<VectorSimulation> cpu;
  std::optional<gpu::VectorSimulation> gpu;
  if (gpu_context)
    gpu.emplace(gpu_context, volume, storage, options, decay);
  else
    cpu.emplace(volume, storage, options, decay);
  VectorAgents agents(count, seed);
  Row r{test, vector_algorithm_name(algorithm), resolution, count, dt, decay};
  std::vector<double> step_ms, generate_ms, blend_ms;
  const bool approximate =
      algorithm != VectorAlgorithm::kBrute && algorithm != VectorAlgorithm::kSplat;
  VectorOptions exact;
  std::int64_t dispatches = 0, submits = 0;
  for (int i = 0; i < steps; ++i) {
    const std::vector<VectorSource> sources = agents.step(dt);
    const auto start = std::chrono::steady_clock::now();
    if (gpu) {
      gpu->step(sources, dt);
    } else {
      cpu->step(sources, dt);
    }
    step_ms.push_back(ms_since(start));
    if (gpu) {
      double device_ms = 0;
      for (const gpu::PassTiming& t : gpu->last_timings()) device_ms += t.ms;
      generate_ms.push_back(device_ms);
      blend_ms.push_back(0);
      dispatches += gpu->last_stats().dispatches;
      submits += gpu->last_stats().submits;
    } else {
      const VectorPassTimes& t = cpu->last_times();
      generate_ms.push_back(t.seed_ms + t.flood_ms + t.search_ms + t.convert_ms);
      blend_ms.push_back(t.blend_ms);
    }
    if (approximate && i % 10 == 9) {  // every tenth step: the error against the definition
      std::vector<std::int32_t> approximate_winners;
      if (gpu_context)
        gpu::generate_vectors(*gpu_context, volume, sources, storage, options,
                              &approximate_winners);
      else
        approximate_winners = vector_winners(volume, sources, options);
      const VectorError e = compare_vector_winners(
          volume, sources, vector_winners(volume, sources, exact), approximate_winners);
      r.percent_differs = std::max(r.percent_differs, e.percent_differs());
      r.max_angle_deg = std::max(r.max_angle_deg, e.max_angle_deg);
      r.max_strength_error = std::max(r.max_strength_error, e.max_strength_error);
    }
  }
  r.dispatches_per_step = static_cast<double>(dispatches) / steps;
  r.submits_per_step = static_cast<double>(submits) / steps;
  const VectorTexture field = gpu ? gpu->field() : cpu->field();
  double strength = 0;
  for (std::int64_t i = 0; i < volume.voxel_count(); ++i) strength += field.get(i).strength;
  r.mean_strength = strength / volume.voxel_count();
  // The first steps warm the caches and the pool: the mean and p99 of the rest.
  const std::size_t skip = std::min<std::size_t>(step_ms.size() / 10, 5);
  std::vector<double> kept(step_ms.begin() + static_cast<std::ptrdiff_t>(skip), step_ms.end());
  // The same steps for the passes' means.
  for (std::size_t i = skip; i < step_ms.size(); ++i) {
    r.generate_ms += generate_ms[i] / static_cast<double>(step_ms.size() - skip);
    r.blend_ms += blend_ms[i] / static_cast<double>(step_ms.size() - skip);
  }
  for (double m : kept) r.step_ms += m;
  r.step_ms /= std::max<std::size_t>(1, kept.size());
  std::sort(kept.begin(), kept.end());
  r.p99_step_ms = kept.empty() ? 0 : kept[std::min(kept.size() - 1, kept.size() * 99 / 100)];
  return r;
}

int run_bench_vectors(const BenchVectorSettings& s) {
  const VectorStorage storage = parse_vector_storage(s.storage);
  Outputs outputs;
  outputs.expect(s.csv, "--csv");
  outputs.expect(s.plot, "--plot");
  const std::string plot_ext = std::filesystem::path(s.plot).extension().string();
  if (!s.plot.empty() && plot_ext != ".svg" && plot_ext != ".png")
    throw UsageError("--plot " + s.plot + ": the plot is written as .svg or .png");
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  const std::shared_ptr<gpu::Context> gpu_context = choose_vector_backend(s.backend);
  const std::string backend = gpu_context ? "vulkan" : "cpu";
  using A = VectorAlgorithm;
  const std::vector<A> all{A::kBrute, A::kSplat, A::kJfa, A::kJfaPlus1, A::kJfaPlus2};
  const double dt = 1.0 / 60;
  std::vector<Row> rows;
  auto add = [&](A a, Vec3i res, int count, double step_dt, double decay) {
    if (!s.algorithms.empty() && std::find(s.algorithms.begin(), s.algorithms.end(),
                                           vector_algorithm_name(a)) == s.algorithms.end())
      return;
    rows.push_back(
        run_case(s.test, a, res, count, step_dt, decay, storage, s.steps, s.seed, gpu_context));
    const Row& r = rows.back();
    std::cerr << "  " << r.algorithm << " " << to_string(res) << " sources " << count << ": "
              << r.step_ms << " ms per step\n";
  };
  const Vec3i r64{64, 64, 64};
  if (s.test == "fidelity") {
    for (A a : all) add(a, r64, 20, dt, 1.0);
  } else if (s.test == "decay") {
    for (double decay : {0.0, 0.5, 1.0, 2.0, 4.0}) add(A::kSplat, r64, 20, dt, decay);
  } else if (s.test == "jfa-sources") {
    for (int n : {1, 5, 10, 20, 50, 100, 200})
      for (A a : {A::kBrute, A::kSplat, A::kJfa}) add(a, r64, n, dt, 1.0);
  } else if (s.test == "jfa-resolution") {
    for (int n : {16, 32, 64, 128})
      for (A a : {A::kBrute, A::kSplat, A::kJfa}) add(a, {n, n, n}, 50, dt, 1.0);
  } else if (s.test == "time-step") {
    for (double hz : {30.0, 60.0, 120.0, 240.0}) add(A::kSplat, r64, 20, 1.0 / hz, 1.0);
  } else if (s.test == "quarter-resolution") {
    for (A a : {A::kSplat, A::kJfa}) {
      add(a, r64, 20, dt, 1.0);
      add(a, {64, 16, 64}, 20, dt, 1.0);
    }
  } else {
    throw UsageError("unknown test " + s.test);
  }
  std::ostringstream csv;
  csv << "test,backend,algorithm,nx,ny,nz,sources,dt_s,decay_per_s,storage,steps,generate_ms,"
         "decay_blend_ms,step_ms,p99_step_ms,percent_source_differs,max_angle_deg,max_strength_"
         "error,mean_strength,dispatches_per_step,submits_per_step\n";
  if (gpu_context)
    std::cout << "Vulkan on " << gpu_context->device().name
              << (gpu_context->device().hardware
                      ? ""
                      : " (a CPU implementation: its times are CPU emulation, not GPU speed)")
              << "\n\n";
  std::cout
      << "| algorithm | resolution | sources | dt (s) | decay/s | generate ms | decay+blend ms | "
         "step ms (p99) | % source differs | max angle (deg) | max strength error |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Row& r : rows) {
    csv << r.test << "," << backend << "," << r.algorithm << "," << r.resolution.x << ","
        << r.resolution.y << "," << r.resolution.z << "," << r.sources << "," << r.dt << ","
        << r.decay << "," << s.storage << "," << s.steps << "," << r.generate_ms << ","
        << r.blend_ms << "," << r.step_ms << "," << r.p99_step_ms << "," << r.percent_differs << ","
        << r.max_angle_deg << "," << r.max_strength_error << "," << r.mean_strength << ","
        << r.dispatches_per_step << "," << r.submits_per_step << "\n";
    char line[512];
    std::snprintf(
        line, sizeof line,
        "| %s | %dx%dx%d | %d | %.4f | %.1f | %.3f | %.3f | %.3f (%.3f) | %.3f | %.2f | %.4f |\n",
        r.algorithm.c_str(), r.resolution.x, r.resolution.y, r.resolution.z, r.sources, r.dt,
        r.decay, r.generate_ms, r.blend_ms, r.step_ms, r.p99_step_ms, r.percent_differs,
        r.max_angle_deg, r.max_strength_error);
    std::cout << line;
  }
  if (!s.csv.empty()) outputs.stage(s.csv, std::string_view(csv.str()));
  if (!s.plot.empty()) {
    // One group per value of the test's swept parameter, one bar per algorithm: ms per step.
    BarChart chart;
    chart.title = "voxfield bench vectors --test " + s.test + " (" + s.storage + ", " + backend +
                  (gpu_context ? " on " + gpu_context->device().name : "") + ")";
    chart.value_label = "ms per step";
    auto group_of = [&](const Row& r) -> std::string {
      char b[64];
      if (s.test == "decay")
        std::snprintf(b, sizeof b, "%.1f", r.decay);
      else if (s.test == "jfa-sources")
        std::snprintf(b, sizeof b, "%d", r.sources);
      else if (s.test == "time-step")
        std::snprintf(b, sizeof b, "%.0f", 1 / r.dt);
      else
        std::snprintf(b, sizeof b, "%dx%dx%d", r.resolution.x, r.resolution.y, r.resolution.z);
      return b;
    };
    chart.group_label = s.test == "decay"         ? "decay per second"
                        : s.test == "jfa-sources" ? "sources (64^3)"
                        : s.test == "time-step"   ? "steps per second"
                                                  : "resolution";
    for (const Row& r : rows) {
      const std::string g = group_of(r);
      if (std::find(chart.groups.begin(), chart.groups.end(), g) == chart.groups.end())
        chart.groups.push_back(g);
      if (std::find(chart.series.begin(), chart.series.end(), r.algorithm) == chart.series.end())
        chart.series.push_back(r.algorithm);
    }
    chart.values.assign(chart.series.size(), std::vector<double>(chart.groups.size(), 0));
    for (const Row& r : rows) {
      const auto si =
          std::find(chart.series.begin(), chart.series.end(), r.algorithm) - chart.series.begin();
      const auto gi =
          std::find(chart.groups.begin(), chart.groups.end(), group_of(r)) - chart.groups.begin();
      chart.values[static_cast<std::size_t>(si)][static_cast<std::size_t>(gi)] = r.step_ms;
    }
    if (plot_ext == ".png")
      outputs.stage(s.plot, render_png(chart));
    else
      outputs.stage(s.plot, std::string_view(render_svg(chart)));
  }
  outputs.commit();
  return 0;
}

}  // namespace

void add_bench_vectors(CLI::App* bench, Action& action) {
  auto s = std::make_shared<BenchVectorSettings>();
  CLI::App* cmd = bench->add_subcommand(
      "vectors", "The vector-field paper's six tests: whole steps, per pass, with JFA's error");
  cmd->add_option("--test", s->test,
                  "fidelity, decay, jfa-sources, jfa-resolution, time-step or quarter-resolution")
      ->check(CLI::IsMember({"fidelity", "decay", "jfa-sources", "jfa-resolution", "time-step",
                             "quarter-resolution"}));
  cmd->add_option("--steps", s->steps, "steps per case (default 60)")->check(CLI::Range(1, 100000));
  cmd->add_option("--storage", s->storage, "rgba8 (default), rgba16f or rgba32f")
      ->check(CLI::IsMember({"rgba8", "rgba16f", "rgba32f"}));
  cmd->add_option("--seed", s->seed, "the agents' random seed");
  cmd->add_option("--algorithms", s->algorithms,
                  "run only these of the test's algorithms (a,b,...)")
      ->delimiter(',')
      ->check(CLI::IsMember({"splat", "brute", "jfa", "jfa+1", "jfa+2"}));
  cmd->add_option("--threads", s->threads, "threads (default: all)")->check(CLI::Range(1, 1024));
  cmd->add_option("--backend", s->backend,
                  "cpu (default), vulkan or auto; on a software Vulkan device (lavapipe) the times "
                  "are CPU emulation")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->add_option("--csv", s->csv, "one row per case");
  cmd->add_option("--plot", s->plot, "ms per step as a grouped bar chart (.png or .svg)");
  cmd->callback([s, &action] { action = [s] { return run_bench_vectors(*s); }; });
}

}  // namespace voxfield::cli
