// voxfield compare IN: every algorithm side by side on one input, time and error against the
// exact transform — the dissertation's tables, with the error columns they lacked.
#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli.h"
#include "field_args.h"
#include "voxfield/parallel.h"

namespace voxfield::cli {
namespace {

struct CompareSettings {
  std::string in, json;
  std::vector<std::string> algorithms;
  int runs = 1;
  FieldArgs field;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

int run_compare(const CompareSettings& s) {
  check_grid_input(s.in, s.field.grid);
  std::optional<ThreadLimit> limit;
  if (s.field.threads > 0) limit.emplace(s.field.threads);
  Outputs outputs({s.in});
  outputs.expect(s.json, "--json");
  for (const auto& name : s.algorithms) (void)parse_algorithm(name);
  set_activity("loading " + s.in);
  const LoadedWorld in = load_world(s.in, s.field.load_options());
  set_activity("comparing the algorithms on " + s.in);
  DistanceOptions o = s.field.options();
  o.domain = in.extent;
  if (o.domain->empty()) throw InvalidArgument(s.in + ": the input holds no volume");
  std::vector<Algorithm> algs;
  if (s.algorithms.empty()) {
    algs = all_algorithms();
  } else {
    for (const auto& name : s.algorithms) algs.push_back(parse_algorithm(name));
  }
  // Default focus for lod: the middle of the volume, a quarter of each extent.
  Box3i focus;
  if (auto f = s.field.focus_box()) {
    focus = *f;
  } else {
    const Box3i d = *o.domain;
    const Vec3i sz = d.size();
    focus = {d.begin + Vec3i{sz.x * 3 / 8, sz.y * 3 / 8, sz.z * 3 / 8},
             d.begin + Vec3i{std::max(sz.x * 5 / 8, sz.x * 3 / 8 + 1),
                             std::max(sz.y * 5 / 8, sz.y * 3 / 8 + 1),
                             std::max(sz.z * 5 / 8, sz.z * 3 / 8 + 1)}};
  }
  const DistanceField exact = compute_distance_field(in.world, o);
  const Vec3i d = o.domain->size();
  std::cout << "voxfield compare: " << s.in << ", " << d.x << "x" << d.y << "x" << d.z << ", "
            << metric_name(o.metric) << (o.signed_distance ? " signed" : "")
            << (o.max_distance > 0 ? ", clamp " + std::to_string(o.max_distance) : "") << ", "
            << max_threads() << " threads, median of " << s.runs << " run(s)\n\n";
  std::cout << std::left << std::setw(14) << "algorithm" << std::right << std::setw(10) << "ms"
            << std::setw(8) << "passes" << std::setw(7) << "iters" << std::setw(10) << "% wrong"
            << std::setw(10) << "max over" << std::setw(10) << "max under" << std::setw(10)
            << "% unsafe"
            << "\n";
  nlohmann::json rows = nlohmann::json::array();
  for (Algorithm alg : algs) {
    AlgorithmOptions a;
    a.algorithm = alg;
    a.focus = focus;
    std::vector<double> times;
    AlgorithmStats stats;
    std::optional<DistanceField> f;
    try {
      for (int r = 0; r < std::max(1, s.runs); ++r) {
        f = compute_distance_field(in.world, o, a, &stats);
        times.push_back(stats.ms);
      }
    } catch (const InvalidArgument& e) {
      std::cout << std::left << std::setw(14) << algorithm_name(alg) << "  skipped: " << e.what()
                << "\n";
      rows.push_back({{"algorithm", algorithm_name(alg)}, {"skipped", e.what()}});
      continue;
    }
    const FieldError e = compare_fields(*f, exact, in.world);
    const double ms = median(times);
    std::cout << std::left << std::setw(14) << algorithm_name(alg) << std::right << std::fixed
              << std::setprecision(1) << std::setw(10) << ms << std::setw(8) << stats.passes
              << std::setw(7) << stats.iterations << std::setprecision(3) << std::setw(10)
              << e.percent_wrong() << std::setprecision(2) << std::setw(10) << e.max_over
              << std::setw(10) << e.max_under << std::setprecision(3) << std::setw(10)
              << e.percent_unsafe() << "\n";
    rows.push_back({{"algorithm", algorithm_name(alg)},
                    {"ms", ms},
                    {"passes", stats.passes},
                    {"iterations", stats.iterations},
                    {"error", error_json(e)}});
  }
  if (!s.json.empty()) {
    nlohmann::json j{
        {"input", s.in},
        {"dims", {d.x, d.y, d.z}},
        {"metric", metric_name(o.metric)},
        {"signed", o.signed_distance},
        {"max_distance", o.max_distance},
        {"threads", max_threads()},
        {"focus",
         {focus.begin.x, focus.begin.y, focus.begin.z, focus.end.x, focus.end.y, focus.end.z}},
        {"algorithms", rows}};
    outputs.stage_json(s.json, j);
  }
  outputs.commit();
  return 0;
}

}  // namespace

void add_compare(CLI::App& app, Action& action) {
  auto s = std::make_shared<CompareSettings>();
  CLI::App* cmd = app.add_subcommand(
      "compare", "Run every algorithm on one input: time and error against the exact field");
  cmd->add_option("IN", s->in, "input .vox, .npy, .vfw or .vdb")->required();
  s->field.add_to(cmd);
  add_grid_option(cmd, s->field.grid);
  cmd->add_option("--algorithms", s->algorithms, "comma-separated subset (default: all)")
      ->delimiter(',');
  cmd->add_option("--runs", s->runs, "runs per algorithm; the median time is shown")
      ->check(CLI::Range(1, 100));
  cmd->add_option("--json", s->json, "also write the table as JSON");
  cmd->callback([s, &action] { action = [s] { return run_compare(*s); }; });
}

}  // namespace voxfield::cli
