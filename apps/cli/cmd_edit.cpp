// voxfield edit IN -e EDITS.jsonl -o FIELD.npy: scripted edits, each followed by an incremental
// exact distance update (and, with --mesh, a re-mesh of the surface's chunks it reaches); writes
// the final field (world, mesh) and per-edit latencies.
#include <algorithm>
#include <fstream>
#include <iostream>
#include <numeric>

#include "backend_choice.h"
#include "cli.h"
#include "field_args.h"
#include "voxfield/distance_executor.h"
#include "voxfield/edit_script.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/mesh_files.h"
#include "voxfield/parallel.h"

namespace voxfield::cli {
namespace {

struct EditSettings {
  std::string in, edits, out, stats, save_world, backend = "cpu";
  std::string mesh, mesh_algorithm = "mc";
  int mesh_chunk = 16;
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
  outputs.expect(s.mesh, "--mesh");
  const std::optional<MeshFormat> mesh_format =
      s.mesh.empty() ? std::nullopt : std::optional<MeshFormat>(mesh_format_of(s.mesh));
  MeshOptions mo;
  mo.algorithm = parse_mesher(s.mesh_algorithm);
  mo.chunk_edge = s.mesh_chunk;
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
  // The surface kept through the edits (its own exact signed field: mesh_chunks.h).
  std::optional<WorldMeshChunks> kept;
  double mesh_build_ms = 0;
  if (mesh_format) {
    set_activity("meshing " + s.in);
    const auto t_mesh = std::chrono::steady_clock::now();
    kept.emplace(world, mo);
    mesh_build_ms = ms_since(t_mesh);
  }

  // A kept mesh needs every change (a repaint re-colours it); the field alone, only the solid
  // and air changes it depends on.
  DirtyRegions dirty(world.voxels.chunk_edge(),
                     kept ? DirtyRegions::Track::kAnyChange : DirtyRegions::Track::kOccupancy);
  std::vector<double> edit_ms, mesh_ms;
  std::vector<std::int64_t> recomputed, changed, remeshed;
  set_activity("applying the edits of " + s.edits);
  for (const Edit& e : edits) {
    const auto t0 = std::chrono::steady_clock::now();
    const EditResult r = apply_edit(world, e, &dirty);
    const auto st = field.update(dirty);
    edit_ms.push_back(ms_since(t0));
    if (kept) {
      const auto t1 = std::chrono::steady_clock::now();
      remeshed.push_back(static_cast<std::int64_t>(kept->update(dirty).size()));
      mesh_ms.push_back(ms_since(t1));
    }
    dirty.clear();
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
  if (kept) {
    set_activity("writing " + s.mesh);
    const Mesh mesh = kept->merged();
    outputs.stage(s.mesh, encode_mesh(mesh, *mesh_format));
    const double mesh_total = std::accumulate(mesh_ms.begin(), mesh_ms.end(), 0.0);
    j["mesh"] = nlohmann::json{
        {"algorithm", mesher_name(mo.algorithm)},
        {"chunk", mo.chunk_edge},
        {"build_ms", mesh_build_ms},
        {"update_ms", mesh_ms},
        {"chunks_remeshed", remeshed},
        {"chunks", kept->chunk_count().x * kept->chunk_count().y * kept->chunk_count().z},
        {"total_ms", mesh_total},
        {"p50_ms", percentile(mesh_ms, 0.5)},
        {"p99_ms", percentile(mesh_ms, 0.99)},
        {"vertices", mesh.vertex_count()},
        {"triangles", mesh.triangle_count()}};
  }
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
  cmd->add_option("--mesh", s->mesh,
                  "also keep the world's surface meshed through the edits (only the chunks each "
                  "edit reaches re-meshed) and write it (.ply, .obj, .stl or .glb): what voxfield "
                  "mesh gives for the edited world");
  cmd->add_option("--mesh-algorithm", s->mesh_algorithm, "mc (default), sn or dc")
      ->check(
          CLI::IsMember({"mc", "sn", "dc", "marching-cubes", "surface-nets", "dual-contouring"}));
  cmd->add_option("--mesh-chunk", s->mesh_chunk, "cells per mesh chunk edge (2..256, default 16)")
      ->check(CLI::Range(2, 256));
  cmd->callback([s, &action] { action = [s] { return run_edit(*s); }; });
}

}  // namespace voxfield::cli
