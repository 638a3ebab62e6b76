// voxfield edit IN -e EDITS.jsonl -o FIELD.npy: scripted edits, each followed by an incremental
// exact distance update; writes the final field (and world), and per-edit latencies.
#include <algorithm>
#include <fstream>
#include <iostream>
#include <numeric>

#include "cli.h"
#include "live_field.h"
#include "field_args.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/parallel.h"

namespace voxfield::cli {
namespace {

struct EditSettings {
  std::string in, edits, out, stats, save_world, backend = "cpu";
  FieldArgs field;
};

Vec3d vec3d(const nlohmann::json& j, const char* key) {
  const auto& v = j.at(key);
  if (!v.is_array() || v.size() != 3) throw std::invalid_argument(std::string("\"") + key + "\" must be [x, y, z]");
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

Vec3i vec3i(const nlohmann::json& j, const char* key) {
  const Vec3d d = vec3d(j, key);
  for (double c : {d.x, d.y, d.z})
    if (c != std::floor(c) || std::abs(c) > (1 << 30)) throw std::invalid_argument(std::string("\"") + key + "\" must hold integers");
  return {static_cast<int>(d[0]), static_cast<int>(d[1]), static_cast<int>(d[2])};
}

// One line of the edit script. Throws std::invalid_argument / nlohmann errors on bad input.
Edit parse_edit(const std::string& line, const std::filesystem::path& base, int chunk_edge) {
  const nlohmann::json j = nlohmann::json::parse(line);
  if (!j.is_object()) throw std::invalid_argument("expected a JSON object");
  Edit e;
  const std::string op = j.at("op").get<std::string>();
  if (op == "place") e.op = EditOp::kPlace;
  else if (op == "carve") e.op = EditOp::kCarve;
  else if (op == "paint") e.op = EditOp::kPaint;
  else throw std::invalid_argument("unknown op \"" + op + "\" (place, carve, paint)");
  const int material = j.value("material", 1);
  if (material < 0 || material > 255) throw std::invalid_argument("material must be 0..255");
  e.material = static_cast<std::uint8_t>(material);
  const std::string shape = j.at("shape").get<std::string>();
  if (shape == "sphere") {
    e.brush = SphereBrush{vec3d(j, "center"), j.at("radius").get<double>()};
  } else if (shape == "box") {
    e.brush = BoxBrush{vec3i(j, "min"), vec3i(j, "max")};
  } else if (shape == "rotated-box") {
    e.brush = RotatedBoxBrush{vec3d(j, "center"), vec3d(j, "half_extent"), j.contains("rotation_deg") ? vec3d(j, "rotation_deg") : Vec3d{0, 0, 0}};
  } else if (shape == "capsule") {
    e.brush = CapsuleBrush{vec3d(j, "a"), vec3d(j, "b"), j.at("radius").get<double>()};
  } else if (shape == "stamp") {
    std::filesystem::path file = j.at("file").get<std::string>();
    if (file.is_relative()) file = base / file;
    auto model = std::make_shared<World>(load_world(file, chunk_edge).world);
    e.brush = StampBrush{std::move(model), j.contains("offset") ? vec3i(j, "offset") : Vec3i{0, 0, 0}};
  } else {
    throw std::invalid_argument("unknown shape \"" + shape + "\" (sphere, box, rotated-box, capsule, stamp)");
  }
  return e;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

int run_edit(const EditSettings& s) {
  std::optional<ThreadLimit> limit;
  if (s.field.threads > 0) limit.emplace(s.field.threads);
  // Parse and check the whole script before touching anything: a bad line writes nothing.
  std::ifstream script(s.edits);
  if (!script) throw IoError(s.edits + ": cannot open");
  const std::filesystem::path base = std::filesystem::path(s.edits).parent_path();
  std::vector<Edit> edits;
  std::string line;
  for (int number = 1; std::getline(script, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      edits.push_back(parse_edit(line, base, s.field.chunk_edge));
    } catch (const Error& e) {
      throw InvalidArgument(s.edits + ": line " + std::to_string(number) + ": " + e.what());
    } catch (const std::exception& e) {
      throw InvalidArgument(s.edits + ": line " + std::to_string(number) + ": " + e.what());
    }
  }

  // The world is bounded to the input's volume: edits reaching outside are clipped to it.
  const LoadedWorld in = load_world(s.in, s.field.chunk_edge);
  if (in.extent.empty()) throw InvalidArgument(s.in + ": the input holds no volume");
  World world(s.field.chunk_edge, in.extent);
  world.palette = in.world.palette;
  {
    std::vector<std::uint8_t> dense(static_cast<std::size_t>(in.extent.volume()));
    in.world.voxels.copy_to_dense(in.extent, dense.data());
    world.voxels.copy_from_dense(in.extent, dense.data());
  }
  DistanceOptions o = s.field.options();
  const auto t_build = std::chrono::steady_clock::now();
  LiveField field(world, o, s.backend);
  const double build_ms = ms_since(t_build);

  DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy);
  std::vector<double> edit_ms;
  std::vector<std::int64_t> recomputed, changed;
  for (const Edit& e : edits) {
    const auto t0 = std::chrono::steady_clock::now();
    const EditResult r = apply_edit(world, e, &dirty);
    const auto st = field.update(dirty);
    dirty.clear();
    edit_ms.push_back(ms_since(t0));
    recomputed.push_back(st.voxels_recomputed);
    changed.push_back(r.voxels_changed);
  }

  write_npy(field_volume(field.field(), field.field().domain), s.out);
  if (!s.save_world.empty()) save_world(world, in.extent, s.save_world);
  const double total = std::accumulate(edit_ms.begin(), edit_ms.end(), 0.0);
  const Vec3i d = in.extent.size();
  nlohmann::json j = s.field.describe(o, d);
  j["backend"] = field.on_gpu() ? "vulkan" : "cpu";
  if (field.on_gpu()) j["gpu"] = field.gpu_json();
  j.update(nlohmann::json{{"build_ms", build_ms},
                   {"edits", edits.size()},
                   {"edit_ms", edit_ms},
                   {"voxels_recomputed", recomputed},
                   {"voxels_changed", changed},
                   {"total_ms", total},
                   {"mean_ms", edit_ms.empty() ? 0 : total / static_cast<double>(edit_ms.size())},
                   {"p50_ms", percentile(edit_ms, 0.5)},
                   {"p99_ms", percentile(edit_ms, 0.99)},
                   {"max_ms", edit_ms.empty() ? 0 : *std::max_element(edit_ms.begin(), edit_ms.end())},
                   {"total_voxels_recomputed", std::accumulate(recomputed.begin(), recomputed.end(), std::int64_t{0})}});
  if (!s.stats.empty()) write_json(j, s.stats);
  std::cerr << "voxfield: " << edits.size() << " edits, " << total << " ms in all (p50 " << percentile(edit_ms, 0.5)
            << " ms, p99 " << percentile(edit_ms, 0.99) << " ms), wrote " << s.out << "\n";
  return 0;
}

}  // namespace

void add_edit(CLI::App& app, Action& action) {
  auto s = std::make_shared<EditSettings>();
  CLI::App* cmd = app.add_subcommand(
      "edit", "Apply scripted edits (JSON lines) with incremental exact distance updates; write the final field");
  cmd->add_option("IN", s->in, "input .vox or .npy (the world is bounded to its volume)")->required();
  cmd->add_option("-e,--edits", s->edits,
                  "edit script, one JSON object per line, e.g. "
                  "{\"op\":\"place\",\"shape\":\"sphere\",\"center\":[40,12,7],\"radius\":6,\"material\":3}; "
                  "ops place/carve/paint; shapes sphere(center,radius), box(min,max inclusive), "
                  "rotated-box(center,half_extent,rotation_deg), capsule(a,b,radius), stamp(file,offset)")
      ->required();
  cmd->add_option("-o,--output", s->out, "output .npy of the final field")->required();
  s->field.add_to(cmd);
  cmd->add_option("--backend", s->backend, "cpu (default), vulkan or auto: where the field lives and is updated")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}));
  cmd->add_option("--stats", s->stats, "write per-edit latency (edit_ms), voxels_recomputed and totals as JSON");
  cmd->add_option("--save-world", s->save_world, "also write the edited world (.npy or .vox)");
  cmd->callback([s, &action] { action = [s] { return run_edit(*s); }; });
}

}  // namespace voxfield::cli
