// voxfield CLI — parsing of the distance-field options and of a .vdb input's --grid.
#include "field_args.h"

#include <sys/resource.h>

#include "cli.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>

namespace voxfield::cli {

void FieldArgs::add_to(CLI::App* cmd) {
  cmd->add_option("--metric", metric, "manhattan, chebyshev or euclidean")
      ->check(CLI::IsMember({"manhattan", "chebyshev", "euclidean"}))
      ->capture_default_str();
  cmd->add_flag("--signed", is_signed,
                "negative distances inside solids (to the nearest air voxel)");
  cmd->add_option("--max-distance", max_distance, "clamp D: values beyond D read D (0 = no clamp)")
      ->check(finite_non_negative());
  cmd->add_option("--storage", storage,
                  "u8, u16 or f32 (integer Euclidean: fixed point, rounded down)")
      ->check(CLI::IsMember({"u8", "u16", "f32"}))
      ->capture_default_str();
  cmd->add_option("--spacing", spacing, "voxel size sx,sy,sz (euclidean only)")
      ->delimiter(',')
      ->expected(3)
      ->check(finite_positive());
  cmd->add_option("--focus", focus,
                  "focus box x0,y0,z0,x1,y1,z1 for lod (min inclusive, max exclusive)")
      ->delimiter(',')
      ->expected(6);
  cmd->add_option("--chunk", chunk_edge, "chunk edge: 8, 16, 32, 64 or 128")
      ->check(CLI::IsMember({8, 16, 32, 64, 128}));
  cmd->add_option("--threads", threads, "threads to use, 1..1024 (default: all cores)")
      ->check(CLI::Range(1, 1024));
}

void add_grid_option(CLI::App* cmd, std::string& grid) {
  cmd->add_option("--grid", grid,
                  "a .vdb input's grid to read the world from, by name (default: voxfield's "
                  "world grid, else the first int32 grid, else the first)");
}

void check_grid_input(const std::string& in, const std::string& grid) {
  if (!grid.empty() && lowercase_extension(in) != ".vdb")
    throw UsageError("--grid picks a .vdb input's grid; " + in + " is not a .vdb file");
}

LoadOptions FieldArgs::load_options() const {
  LoadOptions o;
  o.chunk_edge = chunk_edge;
  o.vdb_grid = grid;
  return o;
}

DistanceOptions FieldArgs::options() const {
  DistanceOptions o;
  o.metric = parse_metric(metric);
  o.signed_distance = is_signed;
  o.max_distance = max_distance;
  o.storage = parse_storage(storage);
  if (!spacing.empty()) o.spacing = {spacing[0], spacing[1], spacing[2]};
  return o;
}

nlohmann::json FieldArgs::describe(const DistanceOptions& o, Vec3i dims) const {
  return {{"metric", metric_name(o.metric)},
          {"signed", o.signed_distance},
          {"max_distance", o.max_distance},
          {"storage", storage_name(o.storage)},
          {"dims", {dims.x, dims.y, dims.z}},
          {"threads", max_threads()},
          {"chunk", chunk_edge}};
}

std::optional<Box3i> FieldArgs::focus_box() const {
  if (focus.empty()) return std::nullopt;
  const Box3i b{{focus[0], focus[1], focus[2]}, {focus[3], focus[4], focus[5]}};
  if (b.empty()) throw UsageError("--focus box " + to_string(b) + " is empty");
  return b;
}

std::vector<std::string> algorithm_names() {
  std::vector<std::string> out;
  for (Algorithm a : all_algorithms()) out.push_back(algorithm_name(a));
  return out;
}

bool algorithm_tracks_sites(const AlgorithmOptions& a, const DistanceOptions& o) {
  World probe(8);
  probe.voxels.set({1, 1, 1}, 1);
  DistanceOptions po = o;
  po.nearest_sites = true;
  po.domain = Box3i::from_size({3, 3, 3});
  AlgorithmOptions pa = a;
  if (pa.focus) pa.focus = Box3i::from_size({3, 3, 3});
  return compute_distance_field(probe, po, pa).sites.has_value();
}

std::size_t peak_rss_bytes() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::size_t>(u.ru_maxrss) * 1024;
}

nlohmann::json error_json(const FieldError& e) {
  return {{"measured_voxels", e.air_voxels},
          {"wrong_voxels", e.wrong},
          {"percent_wrong", e.percent_wrong()},
          {"max_over", e.max_over},
          {"max_under", e.max_under},
          {"unsafe_voxels", e.too_large},
          {"percent_unsafe", e.percent_unsafe()},
          {"too_small_voxels", e.too_small}};
}

// The field's values over `box` as an .npy volume of the storage's dtype.
NpyVolume field_volume(const DistanceField& f, const Box3i& box) {
  return std::visit(
      [&](const auto& g) {
        using T = typename std::decay_t<decltype(g)>::value_type;
        // A dense copy, the volume made of it and its encoding are alive at once.
        require_memory(mul_sat(dense_bytes(box, sizeof(T)), 3), 0, "field output",
                       "a dense copy of " + std::to_string(box.volume()) + " values");
        std::vector<T> dense(static_cast<std::size_t>(box.volume()));
        g.copy_to_dense(box, dense.data());
        const DType t = std::is_same_v<T, float>           ? DType::kFloat32
                        : std::is_same_v<T, std::uint16_t> ? DType::kUInt16
                                                           : DType::kUInt8;
        return make_npy(t, box.size(), dense.data());
      },
      f.values);
}

// Nearest-site offsets as int16 a[x, y, z, 3]; -32768 where there is none.
NpyVolume sites_volume(const Grid<SiteOffset>& g, const Box3i& box) {
  // The offsets, their planes, the volume and its encoding are alive at once.
  require_memory(mul_sat(dense_bytes(box, sizeof(SiteOffset)), 4), 0, "--sites output",
                 "a dense copy of " + std::to_string(box.volume()) + " nearest-site offsets");
  const std::size_t n = static_cast<std::size_t>(box.volume());
  std::vector<SiteOffset> dense(n);
  g.copy_to_dense(box, dense.data());
  std::vector<std::int16_t> planes(3 * n);
  for (std::size_t i = 0; i < n; ++i) {
    planes[i] = dense[i].dx;
    planes[n + i] = dense[i].dy;
    planes[2 * n + i] = dense[i].dz;
  }
  NpyVolume v{DType::kInt16, box.size(), {}, 3};
  v.bytes.resize(planes.size() * sizeof(std::int16_t));
  std::memcpy(v.bytes.data(), planes.data(), v.bytes.size());
  return v;
}

}  // namespace voxfield::cli
