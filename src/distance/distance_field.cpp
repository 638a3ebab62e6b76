// voxfield — the small public functions of voxfield/distance.h: the names of metrics and
// storage types and their parsers, and DistanceField's accessors. The transforms themselves are
// in exact/ (exact, separable) and family/ (the dissertation's approximate algorithms).
#include <string>
#include <variant>

#include "voxfield/distance.h"

namespace voxfield {

const char* metric_name(Metric m) {
  switch (m) {
    case Metric::kManhattan:
      return "manhattan";
    case Metric::kChebyshev:
      return "chebyshev";
    case Metric::kEuclidean:
      return "euclidean";
  }
  return "?";
}

const char* storage_name(Storage s) {
  switch (s) {
    case Storage::kU8:
      return "u8";
    case Storage::kU16:
      return "u16";
    case Storage::kF32:
      return "f32";
  }
  return "?";
}

Metric parse_metric(const std::string& name) {
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    if (name == metric_name(m)) return m;
  throw InvalidArgument("unknown metric \"" + name + "\" (manhattan, chebyshev, euclidean)");
}

Storage parse_storage(const std::string& name) {
  for (Storage s : {Storage::kU8, Storage::kU16, Storage::kF32})
    if (name == storage_name(s)) return s;
  throw InvalidArgument("unknown storage \"" + name + "\" (u8, u16, f32)");
}

double DistanceField::distance(Vec3i p) const {
  return std::visit([&](const auto& g) { return encoding.decode(static_cast<double>(g.get(p))); },
                    values);
}

int DistanceField::chunk_edge() const {
  return std::visit([](const auto& g) { return g.chunk_edge(); }, values);
}

DistanceField compute_distance_field(const World& world, const DistanceOptions& options) {
  return compute_distance_field(world.voxels, options);
}

}  // namespace voxfield
