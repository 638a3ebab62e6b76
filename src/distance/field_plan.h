// voxfield — what every distance algorithm resolves from DistanceOptions before it runs
// (internal): validated options, the domain, the encoding and the effective clamp.
#pragma once

#include <array>
#include <cmath>
#include <limits>

#include "voxfield/distance.h"

namespace voxfield::detail {

struct FieldPlan {
  Metric metric;
  bool is_signed;
  bool sites;
  bool unit_spacing;
  std::array<double, 3> spacing;
  // D in distance units, or +inf. Integer storage turns its range into a clamp.
  double clamp;
  Box3i domain;   // the voxels computed
  Box3i aligned;  // the chunks covering the domain
  DistanceEncoding encoding;
};

// Validates the options (throws InvalidArgument) and resolves the plan. With `part`, the plan
// computes only that part of the domain (a slab of a field computed by several processes,
// distance_slab.h): the options are checked against the whole domain, the memory against the part.
FieldPlan make_field_plan(const Grid<std::uint8_t>& occupancy, const DistanceOptions& options,
                          const Box3i* part = nullptr);

// Exact field values of `out` computed from the sites inside `in` (which must contain `out`; for
// values equal to the whole-domain field's, `in` must hold `out` grown by the clamp's reach,
// clipped to the domain). Writes out.volume() encoded values and, when `sites` is not null, as many
// nearest-site offsets, x fastest. `sites_within`, when given, limits the sites to that box (solid
// voxels of `in` outside it count as empty): the distance to a handful of new sites.
template <class T>
void compute_region(const Grid<std::uint8_t>& occupancy, const FieldPlan& plan, const Box3i& in,
                    const Box3i& out, T* values, SiteOffset* sites,
                    const Box3i* sites_within = nullptr);

// Stored value for a distance d (negative inside a signed field; +-inf when no site is in reach),
// clamped and rounded down as documented in distance.h.
template <class T>
T encode_distance(double d, const FieldPlan& p) {
  const double c = std::clamp(d, -p.clamp, p.clamp);
  if constexpr (std::is_same_v<T, float>) {
    return static_cast<float>(c);
  } else {
    constexpr double kMax = static_cast<double>(std::numeric_limits<T>::max());
    const double scaled = std::floor(c * p.encoding.scale) + static_cast<double>(p.encoding.bias);
    return static_cast<T>(std::clamp(scaled, 0.0, kMax));
  }
}

// The value of voxels outside the domain: +D, or +inf / the type's maximum when unclamped.
template <class T>
T field_background(const FieldPlan& p) {
  return encode_distance<T>(std::numeric_limits<double>::infinity(), p);
}

}  // namespace voxfield::detail
