// voxfield — the field plan (field_plan.h): DistanceOptions validated and resolved, once, into
// what every distance algorithm runs on — the domain and its chunk-aligned cover, the encoding
// of integer storage and the effective clamp — with the memory the field will hold checked
// before anything is allocated.
#include <algorithm>
#include <cmath>
#include <string>

#include "field_plan.h"
#include "voxfield/limits.h"

namespace voxfield::detail {
namespace {

// The smallest box of whole chunks (edge 2^shift) holding `b`.
Box3i chunk_aligned(const Box3i& b, int shift) {
  const int e = 1 << shift;
  const Vec3i lo{(b.begin.x >> shift) * e, (b.begin.y >> shift) * e, (b.begin.z >> shift) * e};
  const Vec3i hi{((b.end.x - 1) >> shift) * e + e, ((b.end.y - 1) >> shift) * e + e,
                 ((b.end.z - 1) >> shift) * e + e};
  return {lo, hi};
}

}  // namespace

FieldPlan make_field_plan(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o,
                          const Box3i* part) {
  if (!(o.max_distance >= 0) || std::isinf(o.max_distance)) {
    throw InvalidArgument("max distance must be a finite number >= 0 (0 = no clamp)");
  }
  for (double s : o.spacing)
    if (!(s > 0) || !std::isfinite(s))
      throw InvalidArgument("voxel spacing must be positive and finite");
  const bool unit_spacing = o.spacing == std::array<double, 3>{1, 1, 1};
  if (!unit_spacing && o.metric != Metric::kEuclidean) {
    throw InvalidArgument(std::string("voxel spacing applies to the euclidean metric only, not ") +
                          metric_name(o.metric));
  }
  if (o.fixed_point_scale < 0 || !std::isfinite(o.fixed_point_scale)) {
    throw InvalidArgument("fixed-point scale must be >= 0");
  }
  FieldPlan p;
  p.metric = o.metric;
  p.is_signed = o.signed_distance;
  p.sites = o.nearest_sites;
  p.unit_spacing = unit_spacing;
  p.spacing = o.spacing;
  p.clamp = o.max_distance > 0 ? o.max_distance : std::numeric_limits<double>::infinity();

  // Encoding.
  if (o.storage != Storage::kF32) {
    const int bits = o.storage == Storage::kU8 ? 8 : 16;
    p.encoding.scale = o.metric != Metric::kEuclidean ? 1.0
                       : o.fixed_point_scale > 0      ? o.fixed_point_scale
                                                      : (bits == 8 ? 4.0 : 16.0);
    p.encoding.bias = o.signed_distance ? (std::int64_t{1} << (bits - 1)) : 0;
    // Integer storage cannot hold more than its range: that range acts as a clamp.
    const double type_max = static_cast<double>((std::int64_t{1} << bits) - 1);
    const double range = (type_max - static_cast<double>(p.encoding.bias)) / p.encoding.scale;
    p.clamp = std::min(p.clamp, range);
    // g is held in place in the output type: it must reach past the clamp along z.
    if (type_max * o.spacing[2] < p.clamp) {
      throw InvalidArgument("voxel spacing " + std::to_string(o.spacing[2]) +
                            " along z is too fine for " + storage_name(o.storage) +
                            " storage with this clamp; use f32");
    }
  }

  // Domain.
  if (o.domain) {
    p.domain = *o.domain;
  } else if (occupancy.bounds()) {
    p.domain = *occupancy.bounds();
  } else {
    const Box3i content = occupancy.content_bounds();
    const double grow =
        o.max_distance > 0
            ? std::ceil(o.max_distance / std::min({o.spacing[0], o.spacing[1], o.spacing[2]}))
            : 1.0;
    p.domain =
        content.empty() ? content : content.grown(static_cast<std::int32_t>(std::min(grow, 1e6)));
  }
  if (!p.domain.empty()) {
    const Vec3i s = p.domain.size();
    const std::int64_t limit = o.nearest_sites ? 32767 : (std::int64_t{1} << 30);
    if (s.x > limit || s.y > limit || s.z > limit) {
      throw InvalidArgument(
          "domain " + to_string(p.domain) + " is too large" +
          (o.nearest_sites ? std::string(" for 16-bit nearest-site offsets") : std::string()));
    }
    if (part) {
      if (!p.domain.contains(*part) || part->empty())
        throw InvalidArgument("the part " + to_string(*part) +
                              " is not a non-empty box of the domain " + to_string(p.domain));
      p.domain = *part;
    }
    p.aligned = chunk_aligned(p.domain, occupancy.chunk_shift());
    // The values over the domain (and the sites) are what the field holds at most: refuse a
    // domain they cannot fit in before anything is allocated.
    const std::uint64_t per_voxel = (o.storage == Storage::kU8    ? 1
                                     : o.storage == Storage::kU16 ? 2
                                                                  : 4) +
                                    (o.nearest_sites ? sizeof(SiteOffset) : 0);
    require_memory(dense_bytes(p.domain, per_voxel), 0, "distance field",
                   "the domain " + to_string(p.domain) + " of " +
                       std::to_string(p.domain.volume()) + " voxels");
  }
  return p;
}

}  // namespace voxfield::detail
