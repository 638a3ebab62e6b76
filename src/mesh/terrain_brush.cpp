// voxfield — terrain brushes: an analytic shape's signed distance (primitives.h) added to the
// terrain with a minimum or subtracted with a maximum, sharp or blended by the polynomial smooth
// minimum (Quilez, "smooth minimum", iquilezles.org: smin(a, b) = min(a, b) - h^2 k / 4 with
// h = max(k - |a - b|, 0) / k, which stays within k / 4 of the sharp minimum and equals it once
// |a - b| >= k).
//
// Locality. Stored values lie within ±clamp. Outside the shape's box grown by clamp + k, the
// brush's distance b is >= clamp + k >= d + k, so both the union and the subtraction give d back
// (|d - b| >= k: the blend vanishes), and the brush cannot win a material there: only samples in
// that box are visited, and the result is the same as applying the brush to every sample (the
// tests check it against exactly that).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "terrain_store.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"
#include "voxfield/primitives.h"

namespace voxfield {

using detail::terrain::Chunk;

namespace {

double smooth_min(double a, double b, double k) {
  if (!(k > 0)) return std::min(a, b);
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - h * h * k * 0.25;
}

double brush_distance(const TerrainBrush& b, const Vec3d& p) {
  switch (b.shape) {
    case TerrainBrush::Shape::kSphere:
      return sdf::sphere(p - b.centre_units, b.radius_units);
    case TerrainBrush::Shape::kBox:
      return sdf::box(p - b.centre_units, b.half_extents_units);
    case TerrainBrush::Shape::kCapsule:
      break;
  }
  return sdf::capsule(p, b.centre_units, b.end_units, b.radius_units);
}

void check_brush(const TerrainBrush& b) {
  const auto finite = [](const Vec3d& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  if (!finite(b.centre_units) || !finite(b.end_units))
    throw InvalidArgument("terrain brush: its position must be finite");
  if (b.shape == TerrainBrush::Shape::kBox) {
    const Vec3d h = b.half_extents_units;
    if (!finite(h) || h.x < 0 || h.y < 0 || h.z < 0)
      throw InvalidArgument("terrain brush: a box's half extents must be finite and >= 0");
  } else if (!std::isfinite(b.radius_units) || !(b.radius_units > 0)) {
    throw InvalidArgument("terrain brush: the radius must be finite and > 0");
  }
  if (!std::isfinite(b.smooth_units) || b.smooth_units < 0)
    throw InvalidArgument("terrain brush: the blend radius must be finite and >= 0");
}

// The shape's bounding box in world units, [lo, hi].
std::pair<Vec3d, Vec3d> brush_bounds(const TerrainBrush& b) {
  switch (b.shape) {
    case TerrainBrush::Shape::kSphere: {
      const Vec3d r{b.radius_units, b.radius_units, b.radius_units};
      return {b.centre_units - r, b.centre_units + r};
    }
    case TerrainBrush::Shape::kBox:
      return {b.centre_units - b.half_extents_units, b.centre_units + b.half_extents_units};
    case TerrainBrush::Shape::kCapsule:
      break;
  }
  const Vec3d r{b.radius_units, b.radius_units, b.radius_units};
  const Vec3d lo{std::min(b.centre_units.x, b.end_units.x),
                 std::min(b.centre_units.y, b.end_units.y),
                 std::min(b.centre_units.z, b.end_units.z)};
  const Vec3d hi{std::max(b.centre_units.x, b.end_units.x),
                 std::max(b.centre_units.y, b.end_units.y),
                 std::max(b.centre_units.z, b.end_units.z)};
  return {lo - r, hi + r};
}

}  // namespace

Box3i TerrainField::apply(const TerrainBrush& brush) {
  check_brush(brush);
  Impl& s = *impl_;
  const TerrainOptions& o = s.options;
  // The samples the brush can change: its box grown by clamp + k, in sample coordinates (one
  // sample wider each side against rounding), clipped to the lattice.
  auto [lo, hi] = brush_bounds(brush);
  const double reach = s.codec.clamp + brush.smooth_units;
  Box3i region;
  for (int a = 0; a < 3; ++a) {
    const double origin = o.origin_units[static_cast<std::size_t>(a)];
    const double first = std::floor((lo[a] - reach - origin) / o.spacing_units) - 1;
    const double last = std::ceil((hi[a] + reach - origin) / o.spacing_units) + 1;
    region.begin[a] = static_cast<int>(std::clamp(first, 0.0, static_cast<double>(o.samples[a])));
    region.end[a] = static_cast<int>(std::clamp(last + 1, 0.0, static_cast<double>(o.samples[a])));
  }
  if (region.empty()) return {};
  const int e = s.edge();
  std::vector<std::size_t> touched;
  for (int z = region.begin.z / e; z <= (region.end.z - 1) / e; ++z)
    for (int y = region.begin.y / e; y <= (region.end.y - 1) / e; ++y)
      for (int x = region.begin.x / e; x <= (region.end.x - 1) / e; ++x)
        touched.push_back(s.chunk_index({x, y, z}));
  // Each touched chunk is rebuilt aside and swapped in after all are built (an allocation that
  // fails leaves the field as it was); its changed samples' box is kept per chunk. At most every
  // touched chunk becomes dense, twice over while the old ones are still held.
  const std::size_t dense_bytes =
      static_cast<std::size_t>(e) * e * e * static_cast<std::size_t>(s.codec.bytes + 1);
  require_memory(mul_sat(2 * touched.size(), dense_bytes), 0,
                 "terrain brush on " + to_string(o.samples),
                 std::to_string(touched.size()) + " chunks made dense");
  std::vector<std::optional<Chunk>> fresh(touched.size());
  std::vector<Box3i> changed(touched.size());
  const bool add = brush.mode == TerrainBrush::Mode::kAdd;
  const double k = brush.smooth_units;
  const std::size_t per_chunk = static_cast<std::size_t>(e) * e * e;
  parallel_for(touched.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t t = begin; t < end; ++t) {
      const Chunk& old = s.chunk[touched[t]];
      const Box3i samples = s.samples_of(s.chunk_coord(touched[t]));
      const Box3i visit = samples.intersect(region);
      // Copied on the first change only: most chunks the grown box touches keep every sample.
      std::optional<Chunk>& c = fresh[t];
      Box3i box;
      for (int z = visit.begin.z; z < visit.end.z; ++z)
        for (int y = visit.begin.y; y < visit.end.y; ++y)
          for (int x = visit.begin.x; x < visit.end.x; ++x) {
            const std::size_t i =
                s.local(x - samples.begin.x, y - samples.begin.y, z - samples.begin.z);
            const std::uint32_t raw = old.raw(i, s.codec.bytes);
            const double d = s.codec.decode(raw);
            const double b = brush_distance(brush, s.position(x, y, z));
            const double next = add ? smooth_min(d, b, k) : -smooth_min(-d, b, k);
            const std::uint32_t code = s.codec.encode(next);
            const bool wins = add && b < d && old.material(i) != brush.material;
            if (code == raw && !wins) continue;
            if (!c) c.emplace(old);
            if (code != raw) {
              if (c->samples.empty()) {  // a uniform chunk made dense
                c->samples.resize(per_chunk * static_cast<std::size_t>(s.codec.bytes));
                for (std::size_t j = 0; j < per_chunk; ++j)
                  c->set_raw(j, s.codec.bytes, old.uniform);
              }
              c->set_raw(i, s.codec.bytes, code);
            }
            if (wins) {
              if (c->materials.empty()) c->materials.assign(per_chunk, old.uniform_material);
              c->materials[i] = brush.material;
            }
            box = box.unite(Box3i{{x, y, z}, {x + 1, y + 1, z + 1}});
          }
      if (!c) continue;
      s.compact(*c, samples);
      changed[t] = box;
    }
  });
  Box3i all;
  for (std::size_t t = 0; t < touched.size(); ++t) {
    if (!fresh[t]) continue;
    s.chunk[touched[t]] = std::move(*fresh[t]);
    all = all.unite(changed[t]);
  }
  return all;
}

}  // namespace voxfield
