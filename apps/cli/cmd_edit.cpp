// voxfield edit IN -e EDITS.jsonl -o FIELD.npy: scripted edits, each followed by an incremental
// exact distance update; writes the final field (and world), and per-edit latencies.
#include <algorithm>
#include <fstream>
#include <iostream>
#include <numeric>

#include "backend_choice.h"
#include "cli.h"
#include "field_args.h"
#include "voxfield/distance_executor.h"
#include "voxfield/edit_script.h"
#include "voxfield/parallel.h"

namespace voxfield::cli {
namespace {

struct EditSettings {
  std::string in, edits, out, stats, save_world, backend = "cpu";
  FieldArgs field;
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1,
                    static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

int run_edit(const EditSettings& s) {
  check_grid_input(s.in, s.field.grid);
  std::optional<ThreadLimit> limit;
  if (s.field.threads > 0) limit.emplace(s.field.threads);
  // Outputs, options and the whole script are checked before the world is loaded: a mistake
  // anywhere costs nothing and writes nothing. A first reading of the script checks it and names
  // the stamps' files, which are inputs too; the second loads the stamps.
  DistanceOptions o = s.field.options();
  set_activity("reading the edit script " + s.edits);
  std::vector<std::filesystem::path> stamps;
  EditScriptOptions check;
  check.load_stamps = false;
  check.stamp_files = &stamps;
  (void)read_edit_script(s.edits, check);
  std::vector<std::string> inputs{s.in, s.edits};
  for (const auto& p : stamps) inputs.push_back(p.string());
  Outputs outputs(inputs);
  outputs.expect(s.out, "-o");
  outputs.expect(s.stats, "--stats");
  outputs.expect_world(s.save_world, "--save-world");
  EditScriptOptions eo;
  eo.chunk_edge = s.field.chunk_edge;
  const std::vector<Edit> edits = read_edit_script(s.edits, eo);

  // The world is bounded to the input's volume: edits reaching outside are clipped to it.
  set_activity("loading " + s.in);
  const LoadedWorld in = load_world(s.in, s.field.load_options());
  if (in.extent.empty()) throw InvalidArgument(s.in + ": the input holds no volume");
  World world = rechunk_world(in.world, s.field.chunk_edge, in.extent, s.in);
  set_activity("building the field of " + s.in);
  const auto t_build = std::chrono::steady_clock::now();
  IncrementalDistanceField field(choose_executor(s.backend), world, o);
  const double build_ms = ms_since(t_build);

  DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy);
  std::vector<double> edit_ms;
  std::vector<std::int64_t> recomputed, changed;
  set_activity("applying the edits of " + s.edits);
  for (const Edit& e : edits) {
    const auto t0 = std::chrono::steady_clock::now();
    const EditResult r = apply_edit(world, e, &dirty);
    const auto st = field.update(dirty);
    dirty.clear();
    edit_ms.push_back(ms_since(t0));
    recomputed.push_back(st.voxels_recomputed);
    changed.push_back(r.voxels_changed);
  }

  set_activity("writing " + s.out);
  outputs.stage(s.out, encode_npy(field_volume(field.field(), field.field().domain)));
  if (!s.save_world.empty()) {
    outputs.stage(s.save_world, encode_world(world, in.extent, world_format_of(s.save_world)));
    note_frame_left_out(world, s.save_world);
  }
  const double total = std::accumulate(edit_ms.begin(), edit_ms.end(), 0.0);
  const Vec3i d = in.extent.size();
  nlohmann::json j = s.field.describe(o, d);
  j["backend"] = field.on_gpu() ? "vulkan" : "cpu";
  if (field.on_gpu()) j["gpu"] = gpu_json(field.executor());
  j.update(nlohmann::json{
      {"build_ms", build_ms},
      {"edits", edits.size()},
      {"edit_ms", edit_ms},
      {"voxels_recomputed", recomputed},
      {"voxels_changed", changed},
      {"total_ms", total},
      {"mean_ms", edit_ms.empty() ? 0 : total / static_cast<double>(edit_ms.size())},
      {"p50_ms", percentile(edit_ms, 0.5)},
      {"p99_ms", percentile(edit_ms, 0.99)},
      {"max_ms", edit_ms.empty() ? 0 : *std::max_element(edit_ms.begin(), edit_ms.end())},
      {"total_voxels_recomputed",
       std::accumulate(recomputed.begin(), recomputed.end(), std::int64_t{0})}});
  if (!s.stats.empty()) outputs.stage_json(s.stats, j);
  outputs.commit();
  std::cerr << "voxfield: " << edits.size() << " edits, " << total << " ms in all (p50 "
            << percentile(edit_ms, 0.5) << " ms, p99 " << percentile(edit_ms, 0.99)
            << " ms), wrote " << s.out << "\n";
  return 0;
}

}  // namespace

void add_edit(CLI::App& app, Action& action) {
  auto s = std::make_shared<EditSettings>();
  CLI::App* cmd = app.add_subcommand("edit",
                                     "Apply scripted edits (JSON lines) with incremental exact "
                                     "distance updates; write the final field");
  cmd->add_option("IN", s->in,
                  "input .vox, .npy, .vfw or .vdb (the world is bounded to its volume)")
      ->required();
  cmd->add_option(
         "-e,--edits", s->edits,
         "edit script, one JSON object per line, e.g. "
         "{\"op\":\"place\",\"shape\":\"sphere\",\"center\":[40,12,7],\"radius\":6,\"material\":3};"
         " "
         "ops place/carve/paint; shapes sphere(center,radius), box(min,max inclusive), "
         "rotated-box(center,half_extent,rotation_deg), capsule(a,b,radius), stamp(file,offset)")
      ->required();
  cmd->add_option("-o,--output", s->out, "output .npy of the final field")->required();
  s->field.add_to(cmd);
  add_grid_option(cmd, s->field.grid);
  cmd->add_option("--backend", s->backend,
                  "cpu (default), vulkan or auto: where the field lives and is updated")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->add_option("--stats", s->stats,
                  "write per-edit latency (edit_ms), voxels_recomputed and totals as JSON");
  cmd->add_option("--save-world", s->save_world,
                  "also write the edited world (.vox, .npy or .vfw, by extension)");
  cmd->callback([s, &action] { action = [s] { return run_edit(*s); }; });
}

}  // namespace voxfield::cli
