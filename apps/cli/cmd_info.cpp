// voxfield info FILE [--json]: what a file holds and what it costs in memory.
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli.h"
#include "field_args.h"

namespace voxfield::cli {
namespace {

struct InfoSettings {
  std::string path;
  bool json = false;
  int chunk_edge = 32;
  std::string grid;
};

nlohmann::json box_json(const Box3i& b) {
  if (b.empty()) return nullptr;
  return {{"min", {b.begin.x, b.begin.y, b.begin.z}},
          {"max_exclusive", {b.end.x, b.end.y, b.end.z}},
          {"size", {b.size().x, b.size().y, b.size().z}}};
}

std::string dims_text(Vec3i s) {
  return std::to_string(s.x) + " x " + std::to_string(s.y) + " x " + std::to_string(s.z);
}

std::string bytes_text(std::size_t bytes) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(1);
  if (bytes >= (std::size_t{1} << 20)) {
    os << bytes / 1048576.0 << " MiB";
  } else if (bytes >= 1024) {
    os << bytes / 1024.0 << " KiB";
  } else {
    os << bytes << " B";
  }
  return os.str();
}

// What both outputs report, computed once.
struct WorldSummary {
  Box3i content;
  GridMemory memory;
  int materials_used = 0;
  std::int64_t solid = 0;

  explicit WorldSummary(const World& w)
      : content(w.voxels.content_bounds()), memory(w.voxels.memory()), solid(w.solid_count()) {
    const auto histogram = w.material_histogram();
    for (int m = 1; m < 256; ++m) materials_used += histogram[m] > 0;
  }
};

int print_text(const InfoSettings& s, const LoadedWorld& in, const WorldSummary& sum);

int run_info(const InfoSettings& s) {
  check_grid_input(s.path, s.grid);
  set_activity("loading " + s.path);
  LoadOptions lo;
  lo.chunk_edge = s.chunk_edge;
  lo.vdb_grid = s.grid;
  const LoadedWorld in = load_world(s.path, lo);
  set_activity("describing " + s.path);
  const WorldSummary sum(in.world);
  if (!s.json) return print_text(s, in, sum);
  const Grid<std::uint8_t>& g = in.world.voxels;
  const Box3i& content = sum.content;
  const GridMemory& mem = sum.memory;
  const int materials_used = sum.materials_used;
  const std::int64_t solid = sum.solid;

  nlohmann::json j;
  j["file"] = s.path;
  j["format"] = world_format_name(in.format);
  j["description"] = in.description;
  j["dims"] = {in.extent.size().x, in.extent.size().y, in.extent.size().z};
  j["extent"] = box_json(in.extent);
  j["bounding_box"] = box_json(content);
  j["solid_voxels"] = solid;
  const VoxelFrame& f = in.world.frame;
  auto vec = [](Vec3d v) { return nlohmann::json{v.x, v.y, v.z}; };
  j["frame"] = {{"origin_world", vec(f.origin_world)},
                {"voxel_size_world", vec(f.voxel_size_world)},
                {"rotation", {vec(f.rotation[0]), vec(f.rotation[1]), vec(f.rotation[2])}}};
  j["palette_entries_used"] = materials_used;
  j["chunks"] = {{"edge", g.chunk_edge()},
                 {"total", g.chunk_count()},
                 {"dense", mem.dense_chunks},
                 {"uniform", mem.uniform_chunks}};
  j["memory"] = {{"bytes", mem.bytes}, {"bytes_per_voxel", mem.bytes_per_voxel()}};
  if (in.vox) {
    const VoxFileInfo& v = *in.vox;
    j["vox"]["version"] = v.version;
    j["vox"]["has_palette"] = v.has_palette;
    j["vox"]["scene_graph"] = v.has_scene_graph;
    nlohmann::json models = nlohmann::json::array();
    for (const auto& m : v.models) {
      models.push_back({{"size", {m.size.x, m.size.y, m.size.z}},
                        {"voxels", m.voxel_count},
                        {"compressed", m.compressed}});
    }
    j["models"] = models;
    j["vox"]["chunk_counts"] = v.chunk_counts;
  }
  // Instances are streamed one by one: a scene graph may hold a million of them.
  // Names and chunk ids come from the file: bytes that are not UTF-8 are replaced, not fatal.
  std::string head = j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  if (!in.vox) {
    std::cout << head << "\n";
    return 0;
  }
  head.resize(head.size() - 2);  // drop "\n}"
  std::cout << head << ",\n  \"instances\": [";
  bool first = true;
  for (const auto& i : in.vox->instances) {
    const nlohmann::json one{
        {"model", i.model}, {"name", i.name}, {"hidden", i.hidden}, {"box", box_json(i.world_box)}};
    std::cout << (first ? "\n    " : ",\n    ")
              << one.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    first = false;
  }
  std::cout << (first ? "]\n}\n" : "\n  ]\n}\n");
  return 0;
}

int print_text(const InfoSettings& s, const LoadedWorld& in, const WorldSummary& sum) {
  const Grid<std::uint8_t>& g = in.world.voxels;
  const Box3i& content = sum.content;
  const GridMemory& mem = sum.memory;
  const int materials_used = sum.materials_used;
  const std::int64_t solid = sum.solid;
  std::cout << "file:          " << s.path << " (" << in.description << ")\n";
  std::cout << "dimensions:    " << dims_text(in.extent.size()) << "\n";
  std::cout << "bounding box:  " << (content.empty() ? std::string("(empty)") : to_string(content))
            << "\n";
  std::cout << "solid voxels:  " << solid << "\n";
  std::cout << "frame:         "
            << (in.world.frame.is_identity() ? std::string("voxel units (the identity)")
                                             : describe(in.world.frame))
            << "\n";
  if (in.vox) {
    const VoxFileInfo& v = *in.vox;
    std::cout << "models:        " << v.models.size();
    std::int64_t stored = 0;
    for (const auto& m : v.models) stored += m.voxel_count;
    std::cout << " (" << stored << " voxels stored)";
    if (v.has_scene_graph) {
      int hidden = 0;
      for (const auto& i : v.instances) hidden += i.hidden;
      std::cout << ", " << v.instances.size() << " instances in the scene graph";
      if (hidden) std::cout << " (" << hidden << " hidden, not imported)";
    }
    std::cout << "\n";
    for (std::size_t i = 0; i < v.models.size() && i < 16; ++i) {
      const auto& m = v.models[i];
      std::cout << "  model " << i << ": " << dims_text(m.size) << ", " << m.voxel_count
                << " voxels" << (m.compressed ? " (TDCZ, zlib)" : "") << "\n";
    }
    if (v.models.size() > 16) std::cout << "  ... " << v.models.size() - 16 << " more\n";
  }
  std::cout << "chunks:        " << g.chunk_count() << " of " << g.chunk_edge() << "^3 ("
            << mem.dense_chunks << " dense, " << mem.uniform_chunks << " uniform)\n";
  std::cout << "memory:        " << bytes_text(mem.bytes) << " (" << std::fixed
            << std::setprecision(3) << mem.bytes_per_voxel()
            << " bytes/voxel over stored chunks)\n";
  std::cout << "palette used:  " << materials_used << " entries\n";
  return 0;
}

}  // namespace

void add_info(CLI::App& app, Action& action) {
  auto s = std::make_shared<InfoSettings>();
  CLI::App* cmd =
      app.add_subcommand("info",
                         "Describe a .vox, .npy, .vfw or .vdb file: dimensions, bounding box, "
                         "solid voxels, models, chunks, memory, palette");
  cmd->add_option("FILE", s->path, "input .vox, .npy, .vfw or .vdb")->required();
  add_grid_option(cmd, s->grid);
  cmd->add_flag("--json", s->json, "print JSON instead of text");
  cmd->add_option("--chunk", s->chunk_edge, "chunk edge used to load the world (8..128)")
      ->check(CLI::IsMember({8, 16, 32, 64, 128}));
  cmd->callback([s, &action] { action = [s] { return run_info(*s); }; });
}

}  // namespace voxfield::cli
