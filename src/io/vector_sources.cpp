// The sources file of `voxfield vectors` (docs/vectors.md, "Files"): JSON, validated as it is read
// so that every refusal names the file, the frame and the source.
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/vector_files.h"

namespace voxfield {
namespace {

using json = nlohmann::json;

constexpr std::size_t kMaxSources = std::size_t{1} << 20;
constexpr double kMaxCoordinate = 1e12;  // world units; beyond, distances lose all precision

struct Reader {
  const std::string& name;

  [[noreturn]] void bad(const std::string& where, const std::string& what) const {
    throw InvalidArgument(name + ": " + where + (where.empty() ? "" : ": ") + what);
  }

  Vec3d point(const json& j, const std::string& where, const char* key) const {
    if (!j.is_array() || j.size() != 3)
      bad(where, std::string("\"") + key + "\" must be [x, y, z]");
    Vec3d p;
    for (int a = 0; a < 3; ++a) {
      if (!j[a].is_number())
        bad(where, std::string("\"") + key + "\" must hold three numbers, got " + j.dump());
      p[a] = j[a].get<double>();
      if (!std::isfinite(p[a]) || std::abs(p[a]) > kMaxCoordinate)
        bad(where, std::string("\"") + key + "\" components must be finite and within +-1e12");
    }
    return p;
  }

  std::vector<VectorSource> sources(const json& list, const std::string& where,
                                    std::size_t& total) const {
    if (!list.is_array()) bad(where, "\"sources\" must be an array");
    std::vector<VectorSource> out;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const std::string at = where + (where.empty() ? "" : ", ") + "source " + std::to_string(i);
      const json& s = list[i];
      if (!s.is_object()) bad(at, "must be an object");
      for (auto it = s.begin(); it != s.end(); ++it)
        if (it.key() != "position" && it.key() != "previous" && it.key() != "radius")
          bad(at, "unknown key \"" + it.key() + "\" (position, previous, radius)");
      if (!s.contains("position")) bad(at, "\"position\" is missing");
      if (!s.contains("radius")) bad(at, "\"radius\" is missing");
      VectorSource src;
      src.position = point(s["position"], at, "position");
      src.previous = s.contains("previous") ? point(s["previous"], at, "previous") : src.position;
      if (!s["radius"].is_number()) bad(at, "\"radius\" must be a number");
      src.radius = s["radius"].get<double>();
      if (!std::isfinite(src.radius) || src.radius <= 0 || src.radius > kMaxCoordinate)
        bad(at, "\"radius\" must be > 0 and at most 1e12, got " + s["radius"].dump());
      if (++total > kMaxSources) bad(at, "more than 2^20 sources in the file");
      out.push_back(src);
    }
    return out;
  }
};

}  // namespace

VectorSourceFrames parse_vector_sources(std::span<const std::uint8_t> bytes,
                                        const std::string& name) {
  json j;
  try {
    j = json::parse(bytes.begin(), bytes.end());
  } catch (const json::parse_error& e) {
    const std::string what = e.what();
    const auto colon = what.find("]: ");
    throw FormatError(
        name, e.byte > 0 ? e.byte - 1 : 0,
        "not valid JSON: " + (colon == std::string::npos ? what : what.substr(colon + 3)));
  } catch (const json::exception& e) {  // a number beyond a double's range
    throw InvalidArgument(name + ": not valid JSON: " + e.what());
  }
  const Reader r{name};
  if (!j.is_object()) r.bad("", "expected a JSON object with \"sources\" or \"frames\"");
  for (auto it = j.begin(); it != j.end(); ++it)
    if (it.key() != "sources" && it.key() != "frames")
      r.bad("", "unknown key \"" + it.key() + "\" (sources, frames)");
  VectorSourceFrames out;
  std::size_t total = 0;
  if (j.contains("sources") == j.contains("frames"))
    r.bad("", "expected exactly one of \"sources\" and \"frames\"");
  if (j.contains("sources")) {
    out.frames.push_back(r.sources(j["sources"], "", total));
    return out;
  }
  const json& frames = j["frames"];
  if (!frames.is_array() || frames.empty()) r.bad("", "\"frames\" must be a non-empty array");
  out.animated = true;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const std::string at = "frame " + std::to_string(f);
    if (!frames[f].is_object() || !frames[f].contains("sources") || frames[f].size() != 1)
      r.bad(at, "must be an object holding \"sources\" only");
    out.frames.push_back(r.sources(frames[f]["sources"], at, total));
  }
  return out;
}

VectorSourceFrames read_vector_sources(const std::filesystem::path& path) {
  // A sources file is small: 64 MiB holds over 2^20 sources written out in full.
  const std::vector<std::uint8_t> bytes = read_file(path, std::uint64_t{64} << 20);
  return parse_vector_sources(bytes, path.string());
}

}  // namespace voxfield
