// Vector fields from voxel worlds (docs/vectors.md, "From voxel worlds"): every solid voxel a
// source of radius `reach`, read straight from the exact nearest-site field — the nearest solid
// voxel is the strongest source, so the definition's winner is the feature transform's site (ties
// as distance.md breaks them) — and kept current under edits by the incremental field.
#include <cmath>
#include <string>

#include "texel_codec.h"
#include "vector_internal.h"
#include "voxfield/error.h"
#include "voxfield/vector_world.h"

namespace voxfield {
namespace {

constexpr double kMaxReach = 16384;  // nearest-site offsets are 16-bit

void check_reach(double reach) {
  if (!std::isfinite(reach) || reach <= 0 || reach >= kMaxReach)
    throw InvalidArgument("world vector field: the reach must be finite and in (0, 16384) voxels");
}

DistanceOptions field_options(const Box3i& box, double reach) {
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.max_distance = reach;
  o.storage = Storage::kF32;
  o.nearest_sites = true;
  o.domain = box;
  return o;
}

// The texel of voxel p from its nearest-site offset.
VectorTexel texel_at(const Grid<SiteOffset>& sites, Vec3i p, double reach) {
  const SiteOffset o = sites.get(p);
  if (o.none()) return {};
  const Vec3d away{-static_cast<double>(o.dx), -static_cast<double>(o.dy),
                   -static_cast<double>(o.dz)};
  const double d = away.length();
  if (!(d < reach)) return {};
  VectorTexel t;
  t.strength = static_cast<float>(1.0 - d / reach);
  if (d > 0) {
    t.x = static_cast<float>(away.x / d);
    t.y = static_cast<float>(away.y / d);
    t.z = static_cast<float>(away.z / d);
  }
  return t;
}

void encode_region(const DistanceField& field, const Box3i& box, const Box3i& region, double reach,
                   VectorTexture& out) {
  if (!field.sites)
    throw InvalidArgument("vectors_from_field: the field was computed without nearest sites");
  const Grid<SiteOffset>& sites = *field.sites;
  const Vec3i n = box.size();
  const Box3i r = region.intersect(box);
  if (r.empty()) return;
  detail::vectors::with_codec(out.storage(), [&](auto codec) {
    using C = decltype(codec);
    std::uint8_t* texels = out.data();
    for (int z = r.begin.z; z < r.end.z; ++z)
      for (int y = r.begin.y; y < r.end.y; ++y)
        for (int x = r.begin.x; x < r.end.x; ++x) {
          const std::int64_t i =
              (x - box.begin.x) +
              static_cast<std::int64_t>(n.x) *
                  ((y - box.begin.y) + static_cast<std::int64_t>(n.y) * (z - box.begin.z));
          C::store(texels + i * C::kBytes, texel_at(sites, {x, y, z}, reach));
        }
  });
}

}  // namespace

VectorVolume world_vector_volume(const Box3i& box) {
  if (box.empty()) throw InvalidArgument("world vector volume: the box is empty");
  VectorVolume v;
  const Vec3i s = box.size();
  v.resolution = s;
  v.size = {static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)};
  v.centre = {box.begin.x + 0.5 * s.x, box.begin.y + 0.5 * s.y, box.begin.z + 0.5 * s.z};
  v.validate();
  return v;
}

VectorTexture vectors_from_field(const DistanceField& field, const Box3i& box, double reach,
                                 VectorStorage storage) {
  check_reach(reach);
  if (field.options.metric != Metric::kEuclidean || field.options.signed_distance)
    throw InvalidArgument("vectors_from_field: the field must be unsigned Euclidean");
  if (field.options.max_distance != 0 && field.options.max_distance < reach)
    throw InvalidArgument("vectors_from_field: the field's clamp is below the reach");
  if (!(field.domain.intersect(box) == box))
    throw InvalidArgument("vectors_from_field: the box " + to_string(box) +
                          " reaches outside the field's domain " + to_string(field.domain));
  const VectorVolume volume = world_vector_volume(box);
  VectorTexture out(volume.resolution, storage);
  encode_region(field, box, box, reach, out);
  return out;
}

WorldVectorField::WorldVectorField(const World& world, const Box3i& box, double reach,
                                   VectorStorage storage)
    : box_(box),
      reach_(reach),
      volume_(world_vector_volume(box)),
      field_((check_reach(reach), world), field_options(box, reach)),
      texture_(volume_.resolution, storage) {
  encode(box_);
}

void WorldVectorField::encode(const Box3i& region) {
  encode_region(field_.field(), box_, region, reach_, texture_);
}

namespace {

// `box` minus the boxes already in `disjoint`, appended to it as disjoint pieces: each overlap
// splits what remains into at most six slabs (below and above the overlap along x, then y, then z).
void add_disjoint(std::vector<Box3i>& disjoint, const Box3i& box) {
  std::vector<Box3i> pieces{box};
  for (std::size_t k = 0, existing = disjoint.size(); k < existing && !pieces.empty(); ++k) {
    const Box3i& a = disjoint[k];
    std::vector<Box3i> next;
    for (Box3i rest : pieces) {
      const Box3i overlap = rest.intersect(a);
      if (overlap.empty()) {
        next.push_back(rest);
        continue;
      }
      for (int axis = 0; axis < 3; ++axis) {
        if (rest.begin[axis] < overlap.begin[axis]) {
          Box3i below = rest;
          below.end[axis] = overlap.begin[axis];
          next.push_back(below);
          rest.begin[axis] = overlap.begin[axis];
        }
        if (overlap.end[axis] < rest.end[axis]) {
          Box3i above = rest;
          above.begin[axis] = overlap.end[axis];
          next.push_back(above);
          rest.end[axis] = overlap.end[axis];
        }
      }  // what remains of `rest` is the overlap itself, already covered
    }
    pieces = std::move(next);
  }
  disjoint.insert(disjoint.end(), pieces.begin(), pieces.end());
}

}  // namespace

std::int64_t WorldVectorField::update(const DirtyRegions& dirty) {
  field_.update(dirty);
  // A changed voxel moves the nearest site of voxels within the reach of it only. The changed
  // boxes are per chunk, so grown by the reach they overlap: each texel is encoded once.
  const std::int32_t grow = static_cast<std::int32_t>(std::ceil(reach_)) + 1;
  std::vector<Box3i> regions;
  const std::vector<Box3i> boxes = dirty.boxes();
  if (boxes.size() > 64) {
    // Cutting n boxes apart costs n^2: past a few dozen (an edit over many chunks) their bounding
    // box, encoded once, costs less.
    Box3i all;
    for (const Box3i& b : boxes) all = all.unite(b.grown(grow).intersect(box_));
    if (!all.empty()) regions.push_back(all);
  } else {
    for (const Box3i& b : boxes) {
      const Box3i r = b.grown(grow).intersect(box_);
      if (!r.empty()) add_disjoint(regions, r);
    }
  }
  std::int64_t texels = 0;
  for (const Box3i& r : regions) {
    encode(r);
    texels += r.volume();
  }
  return texels;
}

}  // namespace voxfield
