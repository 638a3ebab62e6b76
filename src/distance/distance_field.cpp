// voxfield — the small public functions of voxfield/distance.h: the names of metrics and
// storage types and their parsers, and DistanceField's accessors. The transforms themselves are
// in exact/ (exact, separable) and family/ (the dissertation's approximate algorithms).
#include <string>
#include <variant>

#include "voxfield/distance.h"
#include "voxfield/hash.h"

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

std::uint64_t content_hash(const DistanceField& f) {
  const std::int32_t box[6] = {f.domain.begin.x, f.domain.begin.y, f.domain.begin.z,
                               f.domain.end.x,   f.domain.end.y,   f.domain.end.z};
  std::uint64_t h = fnv1a(kFnvOffset, box, sizeof box);
  const double encoding[2] = {f.encoding.scale, static_cast<double>(f.encoding.bias)};
  h = fnv1a(h, encoding, sizeof encoding);
  if (f.domain.empty()) return h;
  // Slab by slab along z, so a large field is never copied whole.
  const Vec3i n = f.domain.size();
  std::visit(
      [&](const auto& g) {
        using T = typename std::decay_t<decltype(g)>::value_type;
        std::vector<T> slab(static_cast<std::size_t>(n.x) * n.y);
        for (int z = f.domain.begin.z; z < f.domain.end.z; ++z) {
          g.copy_to_dense(Box3i{{f.domain.begin.x, f.domain.begin.y, z},
                                {f.domain.end.x, f.domain.end.y, z + 1}},
                          slab.data());
          h = fnv1a(h, slab.data(), slab.size() * sizeof(T));
        }
      },
      f.values);
  if (f.sites) {
    std::vector<SiteOffset> slab(static_cast<std::size_t>(n.x) * n.y);
    for (int z = f.domain.begin.z; z < f.domain.end.z; ++z) {
      f.sites->copy_to_dense(
          Box3i{{f.domain.begin.x, f.domain.begin.y, z}, {f.domain.end.x, f.domain.end.y, z + 1}},
          slab.data());
      for (const SiteOffset& s : slab) {
        const std::int16_t d[3] = {s.dx, s.dy, s.dz};  // the offsets, never the padding
        h = fnv1a(h, d, sizeof d);
      }
    }
  }
  return h;
}

int DistanceField::chunk_edge() const {
  return std::visit([](const auto& g) { return g.chunk_edge(); }, values);
}

DistanceField compute_distance_field(const World& world, const DistanceOptions& options) {
  DistanceField f = compute_distance_field(world.voxels, options);
  f.frame = world.frame;
  return f;
}

}  // namespace voxfield
