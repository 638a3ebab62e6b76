// voxfield — the edit-script parser (voxfield/edit_script.h), on nlohmann::json (the JSON library
// the CLI already uses: a complete, well-tested parser we do not write ourselves).
#include "voxfield/edit_script.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "voxfield/file.h"
#include "voxfield/world_io.h"

namespace voxfield {
namespace {

using nlohmann::json;

[[noreturn]] void bad(const std::string& what) {
  throw InvalidArgument(what);
}

double number(const json& j, const std::string& key, double lo, double hi) {
  if (!j.is_number()) bad("\"" + key + "\" must be a number");
  const double v = j.get<double>();
  if (!std::isfinite(v) || v < lo || v > hi) {
    bad("\"" + key + "\" is " + j.dump() + ", outside " + json(lo).dump() + ".." + json(hi).dump());
  }
  return v;
}

const json& required(const json& j, const std::string& key) {
  auto it = j.find(key);
  if (it == j.end()) bad("missing \"" + key + "\"");
  return *it;
}

constexpr double kCoord = static_cast<double>(kCoordLimit);

Vec3d point(const json& j, const std::string& key, double lo = -kCoord, double hi = kCoord) {
  const json& v = required(j, key);
  if (!v.is_array() || v.size() != 3) bad("\"" + key + "\" must be [x, y, z]");
  Vec3d out;
  for (int k = 0; k < 3; ++k) out[k] = number(v[static_cast<std::size_t>(k)], key, lo, hi);
  return out;
}

Vec3i integer_point(const json& j, const std::string& key) {
  const Vec3d d = point(j, key, -kCoord, kCoord - 1);
  for (int k = 0; k < 3; ++k)
    if (std::floor(d[k]) != d[k])
      bad("\"" + key + "\" must hold integers, got " + required(j, key).dump());
  return {static_cast<int>(d.x), static_cast<int>(d.y), static_cast<int>(d.z)};
}

void only_keys(const json& j, std::initializer_list<const char*> allowed) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) bad("unknown key \"" + it.key() + "\" for this shape");
  }
}

}  // namespace

Edit parse_edit_line(std::string_view line, const EditScriptOptions& options) {
  json j;
  try {
    j = json::parse(line.begin(), line.end());
  } catch (const json::exception& e) {
    // A syntax error, or a number too large for a double (out_of_range 406, found by
    // fuzz_edit_script). nlohmann's message starts with its own error id; keep what follows.
    const std::string what = e.what();
    const auto colon = what.find("]: ");
    bad("not valid JSON: " + (colon == std::string::npos ? what : what.substr(colon + 3)));
  }
  if (!j.is_object()) bad("expected a JSON object");
  Edit e;
  const json& op = required(j, "op");
  if (!op.is_string()) bad("\"op\" must be a string");
  const std::string op_name = op.get<std::string>();
  if (op_name == "place")
    e.op = EditOp::kPlace;
  else if (op_name == "carve")
    e.op = EditOp::kCarve;
  else if (op_name == "paint")
    e.op = EditOp::kPaint;
  else
    bad("unknown op \"" + op_name + "\" (place, carve, paint)");
  int material = 1;
  if (auto it = j.find("material"); it != j.end()) {
    const double m = number(*it, "material", 0, 255);
    if (std::floor(m) != m) bad("\"material\" must be an integer 0..255, got " + it->dump());
    material = static_cast<int>(m);
  }
  if (e.op != EditOp::kCarve && material == 0) {
    bad("\"material\" 0 is air: " + op_name + " needs 1..255 (carve removes voxels)");
  }
  e.material =
      static_cast<std::uint8_t>(e.op == EditOp::kCarve ? (material == 0 ? 1 : material) : material);
  const json& shape_j = required(j, "shape");
  if (!shape_j.is_string()) bad("\"shape\" must be a string");
  const std::string shape = shape_j.get<std::string>();
  if (shape == "sphere") {
    only_keys(j, {"op", "shape", "material", "center", "radius"});
    e.brush = SphereBrush{point(j, "center"), number(required(j, "radius"), "radius", 0, kCoord)};
  } else if (shape == "box") {
    only_keys(j, {"op", "shape", "material", "min", "max"});
    const BoxBrush b{integer_point(j, "min"), integer_point(j, "max")};
    for (int k = 0; k < 3; ++k) {
      if (b.min[k] > b.max[k])
        bad("box \"min\" " + to_string(b.min) + " exceeds \"max\" " + to_string(b.max) +
            " on axis " + "xyz"[k]);
    }
    e.brush = b;
  } else if (shape == "rotated-box") {
    only_keys(j, {"op", "shape", "material", "center", "half_extent", "rotation_deg"});
    e.brush = RotatedBoxBrush{
        point(j, "center"), point(j, "half_extent", 0, kCoord),
        j.contains("rotation_deg") ? point(j, "rotation_deg", -1e6, 1e6) : Vec3d{0, 0, 0}};
  } else if (shape == "capsule") {
    only_keys(j, {"op", "shape", "material", "a", "b", "radius"});
    e.brush = CapsuleBrush{point(j, "a"), point(j, "b"),
                           number(required(j, "radius"), "radius", 0, kCoord)};
  } else if (shape == "stamp") {
    only_keys(j, {"op", "shape", "material", "file", "offset"});
    const json& f = required(j, "file");
    if (!f.is_string() || f.get<std::string>().empty()) bad("\"file\" must be a file name");
    const Vec3i offset = j.contains("offset") ? integer_point(j, "offset") : Vec3i{0, 0, 0};
    std::shared_ptr<World> model;
    std::filesystem::path file = f.get<std::string>();
    if (file.is_relative()) file = options.base_dir / file;
    if (options.stamp_files) options.stamp_files->push_back(file);
    if (options.load_stamps) {
      LoadOptions lo;
      lo.chunk_edge = options.chunk_edge;
      lo.memory_limit_bytes = options.memory_limit_bytes;
      model = std::make_shared<World>(load_world(file, lo).world);
    }
    e.brush = StampBrush{std::move(model), offset};
    if (!options.load_stamps) return e;  // validate_edit needs the model
  } else {
    bad("unknown shape \"" + shape + "\" (sphere, box, rotated-box, capsule, stamp)");
  }
  validate_edit(e);
  return e;
}

std::vector<Edit> parse_edit_script(std::span<const std::uint8_t> text, const std::string& name,
                                    const EditScriptOptions& options) {
  std::vector<Edit> edits;
  std::size_t start = 0;
  for (int number = 1; start < text.size(); ++number) {
    std::size_t end = start;
    while (end < text.size() && text[end] != '\n') ++end;
    const std::string_view line(reinterpret_cast<const char*>(text.data()) + start, end - start);
    if (line.find_first_not_of(" \t\r") != std::string_view::npos) {
      try {
        edits.push_back(parse_edit_line(line, options));
      } catch (const Error& e) {
        throw FormatError(name, start, "line " + std::to_string(number) + ": " + e.what());
      }
    }
    start = end + 1;
  }
  return edits;
}

std::vector<Edit> read_edit_script(const std::filesystem::path& path, EditScriptOptions options) {
  if (options.base_dir.empty()) options.base_dir = path.parent_path();
  const std::vector<std::uint8_t> bytes = read_file(path, std::uint64_t{1} << 30);
  return parse_edit_script(bytes, path.string(), options);
}

}  // namespace voxfield
