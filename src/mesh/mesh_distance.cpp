// Signed distance fields of triangle meshes, sampled at voxel centres, in three steps:
//
// 1. The narrow band: every triangle visits the voxels within `band` of its bounding box and
//    keeps, per voxel, the exact distance to the nearest triangle (Ericson's point-triangle
//    distance) and which triangle that is — the scan-conversion of Mauch's closest point
//    transform, with boxes in place of his characteristic polyhedra.
// 2. Beyond the band: the voxels within half a voxel diagonal of the surface are sites, and
//    voxfield's exact Euclidean transform (Maurer et al. 2003) finds every other voxel's nearest
//    site; the voxel then takes its exact distance to that site's triangle. A distance to a real
//    triangle is never below the true distance, and the nearest surface voxel's triangle is almost
//    always the nearest triangle (docs/mesh_input.md measures how close it comes).
// 3. The sign from the generalized winding number (winding_number.cpp): negative where it is at
//    least 1/2, so meshes with holes still get an inside.
#include <algorithm>
#include <cmath>
#include <limits>

#include "mesh_triangles.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/interrupt.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_voxelize.h"
#include "voxfield/parallel.h"

namespace voxfield {
namespace {

constexpr int kBandSlabDepth = 4;      // z layers per unit of parallel work in the band
constexpr int kMaxPasses = 64;         // beyond the band; in the tests they settle within a handful
constexpr double kImprovement = 1e-4;  // voxels: a nearer triangle must win by more than this
// The 26 neighbours. Only the 6 face neighbours halves the time but leaves errors of 0.13 voxels
// where the 26 leave under 0.05 (the brute-force test's bound).
constexpr auto kNeighbours = [] {
  std::array<std::array<int, 3>, 26> n{};
  int k = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dx != 0 || dy != 0 || dz != 0) n[k++] = {dx, dy, dz};
  return n;
}();

struct Band {
  std::vector<float> distance;        // +inf outside the band
  std::vector<std::int32_t> nearest;  // the nearest triangle, -1 outside the band
};

// Step 1. Triangles are bucketed by the z slabs their grown boxes reach, then each slab is swept
// by one thread: no two threads write a voxel, and ties go to the lower triangle index, so the
// result does not depend on the thread count.
Band narrow_band(const TriangleMesh& mesh, const Box3i& box, double v, double band,
                 std::uint64_t memory_limit, Progress& progress) {
  const Vec3i size = box.size();
  const std::size_t count = static_cast<std::size_t>(box.volume());
  Band out{std::vector<float>(count, std::numeric_limits<float>::infinity()),
           std::vector<std::int32_t>(count, -1)};
  const int slabs = (size.z + kBandSlabDepth - 1) / kBandSlabDepth;
  std::vector<std::vector<std::uint32_t>> bucket(static_cast<std::size_t>(slabs));
  struct Range {
    std::array<int, 3> lo, hi;  // local voxel indices, inclusive
  };
  std::vector<Range> ranges(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    Range& r = ranges[t];
    bool empty = false;
    for (int k = 0; k < 3; ++k) {
      double lo = HUGE_VAL, hi = -HUGE_VAL;
      for (std::uint32_t p : mesh.triangles[t]) {
        lo = std::min(lo, mesh.positions[p][k]);
        hi = std::max(hi, mesh.positions[p][k]);
      }
      // Voxels whose centre (i + 1/2) v lies within band of [lo, hi], as local indices.
      r.lo[k] = std::max(0, static_cast<int>(std::ceil((lo - band) / v - 0.5)) - box.begin[k]);
      r.hi[k] =
          std::min(size[k] - 1, static_cast<int>(std::floor((hi + band) / v - 0.5)) - box.begin[k]);
      empty |= r.lo[k] > r.hi[k];
    }
    if (empty) r.lo[2] = r.hi[2] + 1;  // no slab
  }
  // The buckets, counted before they are filled: long slivers reach many slabs each.
  std::uint64_t entries = 0;
  for (const Range& r : ranges)
    if (r.lo[2] <= r.hi[2])
      entries +=
          static_cast<std::uint64_t>(r.hi[2] / kBandSlabDepth - r.lo[2] / kBandSlabDepth + 1);
  require_memory(mul_sat(entries, 4), memory_limit, "mesh distance field",
                 "the triangles' slab lists (" + std::to_string(entries) + " entries)");
  for (std::size_t t = 0; t < ranges.size(); ++t) {
    const Range& r = ranges[t];
    if (r.lo[2] > r.hi[2]) continue;
    for (int s = r.lo[2] / kBandSlabDepth; s <= r.hi[2] / kBandSlabDepth; ++s)
      bucket[static_cast<std::size_t>(s)].push_back(static_cast<std::uint32_t>(t));
  }
  const detail::VoxelCentres centres{box, v};
  parallel_for(static_cast<std::size_t>(slabs), 1, [&](std::size_t s0, std::size_t s1) {
    for (std::size_t s = s0; s < s1; ++s) {
      if (!progress.keep_going()) return;
      const int z_begin = static_cast<int>(s) * kBandSlabDepth;
      const int z_end = std::min(size.z, z_begin + kBandSlabDepth);
      for (std::uint32_t t : bucket[s]) {
        const Range& r = ranges[t];
        const auto& tri = mesh.triangles[t];
        const auto &a = mesh.positions[tri[0]], &b = mesh.positions[tri[1]],
                   &c = mesh.positions[tri[2]];
        for (int z = std::max(z_begin, r.lo[2]); z < std::min(z_end, r.hi[2] + 1); ++z)
          for (int y = r.lo[1]; y <= r.hi[1]; ++y) {
            const std::size_t row = (static_cast<std::size_t>(z) * size.y + y) * size.x;
            int x0, x1;
            if (!detail::triangles::row_near_plane(a, b, c, centres.coordinate(1, y),
                                                   centres.coordinate(2, z), band, v, box.begin.x,
                                                   r.lo[0], r.hi[0], &x0, &x1))
              continue;
            for (int x = x0; x <= x1; ++x) {
              const double d = point_triangle_distance(centres.at(x, y, z), a, b, c);
              if (d > band) continue;
              const float df = static_cast<float>(d);
              float& best = out.distance[row + x];
              std::int32_t& who = out.nearest[row + x];
              if (df < best || (df == best && static_cast<std::int32_t>(t) < who)) {
                best = df;
                who = static_cast<std::int32_t>(t);
              }
            }
          }
      }
      progress.advance();
    }
  });
  return out;
}

// Step 2. The sites: voxels within half a voxel diagonal of the surface — every surface point lies
// in some voxel, within that reach of its centre, so no part of the surface lacks a site. Each
// voxel beyond the band starts from its nearest site's triangle. Equidistant sites make that
// choice arbitrary (a voxel inside a box, as near its floor as its wall in voxels, may take the
// wall), so passes follow: a voxel tries its 26 neighbours' triangles and keeps the nearest, until
// a pass changes nothing. Passes read the last pass and write a new one: the result does not
// depend on the threads.
void beyond_band(const TriangleMesh& mesh, const Box3i& box, double v, const Band& band,
                 std::vector<float>& values, Progress& progress) {
  const Vec3i size = box.size();
  const std::size_t count = band.distance.size();
  const float site_reach = static_cast<float>(0.5 * std::sqrt(3.0) * v);
  std::vector<std::uint8_t> sites(count, 0);
  for (std::size_t i = 0; i < count; ++i) sites[i] = band.distance[i] <= site_reach ? 1 : 0;
  Grid<std::uint8_t> occupancy(Grid<std::uint8_t>::kDefaultChunkEdge, 0, box);
  occupancy.copy_from_dense(box, sites.data());
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.nearest_sites = true;
  o.domain = box;
  const DistanceField transform = compute_distance_field(occupancy, o);
  const detail::VoxelCentres centres{box, v};
  const auto distance_to = [&](int x, int y, int z, std::int32_t t) {
    const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
    return static_cast<float>(point_triangle_distance(centres.at(x, y, z), mesh.positions[tri[0]],
                                                      mesh.positions[tri[1]],
                                                      mesh.positions[tri[2]]));
  };
  const auto index = [&](int x, int y, int z) {
    return (static_cast<std::size_t>(z) * size.y + y) * size.x + x;
  };
  std::vector<std::int32_t> nearest = band.nearest;
  parallel_for(static_cast<std::size_t>(size.z), 1, [&](std::size_t z0, std::size_t z1) {
    for (int z = static_cast<int>(z0); z < static_cast<int>(z1); ++z)
      for (int y = 0; y < size.y; ++y)
        for (int x = 0; x < size.x; ++x) {
          const std::size_t i = index(x, y, z);
          if (band.nearest[i] >= 0) continue;
          const Vec3i p = box.begin + Vec3i{x, y, z};
          const SiteOffset off = transform.sites->get(p);
          if (off.none()) continue;  // no site at all: a mesh of zero extent within its box
          const Vec3i q = Vec3i{p.x + off.dx, p.y + off.dy, p.z + off.dz} - box.begin;
          nearest[i] = band.nearest[index(q.x, q.y, q.z)];
          values[i] = distance_to(x, y, z, nearest[i]);
        }
  });
  // Only the neighbours of last pass's changes are asked again, and a triangle must be nearer by
  // more than kImprovement voxels to replace the one held: the rounding of nearly equidistant
  // triangles (a scanned surface's many small ones) would otherwise ripple on pass after pass.
  const float improvement = static_cast<float>(kImprovement * v);
  std::vector<std::uint32_t> changed;  // voxel indices (a box holds < 2^32: memory limits it first)
  for (std::size_t i = 0; i < count; ++i)
    if (band.nearest[i] < 0 && nearest[i] >= 0) changed.push_back(static_cast<std::uint32_t>(i));
  std::vector<std::uint32_t> stamp(count, 0), asked;
  std::vector<std::int32_t> answer;
  const std::size_t plane = static_cast<std::size_t>(size.x) * size.y;
  for (int pass = 0; pass < kMaxPasses && !changed.empty(); ++pass) {
    if (!progress.keep_going()) return;
    asked.clear();
    if (pass == 0) {
      asked = changed;
    } else {
      for (const std::uint32_t c : changed) {
        const int x = static_cast<int>(c % size.x), y = static_cast<int>(c / size.x % size.y),
                  z = static_cast<int>(c / plane);
        for (const auto& s : kNeighbours) {
          const int nx = x + s[0], ny = y + s[1], nz = z + s[2];
          if (nx < 0 || ny < 0 || nz < 0 || nx >= size.x || ny >= size.y || nz >= size.z) continue;
          const std::size_t j = index(nx, ny, nz);
          if (band.nearest[j] >= 0 || nearest[j] < 0 ||
              stamp[j] == static_cast<std::uint32_t>(pass))
            continue;
          stamp[j] = static_cast<std::uint32_t>(pass);
          asked.push_back(static_cast<std::uint32_t>(j));
        }
      }
    }
    answer.assign(asked.size(), -1);
    std::vector<float> answer_distance(asked.size());
    parallel_for(asked.size(), 256, [&](std::size_t b, std::size_t e) {
      std::int32_t tried[27];
      for (std::size_t a = b; a < e; ++a) {
        const std::size_t i = asked[a];
        const int x = static_cast<int>(i % size.x), y = static_cast<int>(i / size.x % size.y),
                  z = static_cast<int>(i / plane);
        std::int32_t best = nearest[i];
        float best_d = values[i];
        int n_tried = 0;
        tried[n_tried++] = best;
        for (const auto& s : kNeighbours) {
          const int nx = x + s[0], ny = y + s[1], nz = z + s[2];
          if (nx < 0 || ny < 0 || nz < 0 || nx >= size.x || ny >= size.y || nz >= size.z) continue;
          const std::int32_t t = nearest[index(nx, ny, nz)];
          if (t < 0 || std::find(tried, tried + n_tried, t) != tried + n_tried) continue;
          tried[n_tried++] = t;
          const float d = distance_to(x, y, z, t);
          if (d < best_d - improvement) {
            best_d = d;
            best = t;
          }
        }
        if (best != nearest[i]) {
          answer[a] = best;
          answer_distance[a] = best_d;
        }
      }
    });
    // Every answer read the last pass only; now they take effect together.
    changed.clear();
    for (std::size_t a = 0; a < asked.size(); ++a)
      if (answer[a] >= 0) {
        nearest[asked[a]] = answer[a];
        values[asked[a]] = answer_distance[a];
        changed.push_back(asked[a]);
      }
  }
}

}  // namespace

float MeshDistanceField::at(Vec3i p) const {
  const Vec3i s = box.size();
  return values[static_cast<std::size_t>(p.x - box.begin.x) +
                static_cast<std::size_t>(s.x) *
                    (static_cast<std::size_t>(p.y - box.begin.y) +
                     static_cast<std::size_t>(s.y) * static_cast<std::size_t>(p.z - box.begin.z))];
}

MeshDistanceField mesh_distance_field(const TriangleMesh& mesh,
                                      const MeshDistanceOptions& options) {
  if (!(options.band_voxels >= 1) || !(options.band_voxels <= 64))
    throw InvalidArgument("mesh distance field: the band must be 1..64 voxels");
  if (!(options.max_distance >= 0) || !std::isfinite(options.max_distance))
    throw InvalidArgument("mesh distance field: the clamp must be >= 0 and finite");
  const Box3i box = mesh_voxel_box(mesh, options);
  // Per voxel: the band's distance and triangle (8 bytes), the sites and their grid (2), the
  // transform's field and nearest-site offsets (4 + 6), the far field's triangles and stamps (8),
  // its lists (up to 12), the output (4); the sign's regions and queue (8), masks (2) and boundary
  // lists (up to 16) come after the transform is gone. 56 covers them all at once. And the
  // winding number's tree: about 120 bytes a triangle.
  require_memory(add_sat(mul_sat(static_cast<std::uint64_t>(box.volume()), 56),
                         mul_sat(mesh.triangles.size(), 120)),
                 options.memory_limit_bytes, "mesh distance field",
                 "a box of " + to_string(box.size()) + " voxels");
  const double v = options.voxel_size;
  const Vec3i size = box.size();
  const std::size_t count = static_cast<std::size_t>(box.volume());
  const int slabs = (size.z + kBandSlabDepth - 1) / kBandSlabDepth;
  Progress progress(options.interrupter, "mesh distance field",
                    slabs + (options.signed_distance ? size.z : 0));
  // A clamp within the band needs no more than the clamp, and two voxels at least: the sign's
  // regions must keep their distance from the surface (mesh_sign.cpp). Nothing beyond the clamp
  // then needs step 2.
  const double clamp = options.max_distance;
  const bool band_only = clamp > 0 && clamp <= options.band_voxels * v;
  const double band_width = band_only ? std::max(clamp, 2 * v) : options.band_voxels * v;
  const Band band = narrow_band(mesh, box, v, band_width, options.memory_limit_bytes, progress);
  progress.throw_if_cancelled();

  MeshDistanceField out;
  out.box = box;
  out.voxel_size = v;
  out.values.assign(band.distance.begin(), band.distance.end());
  for (float d : band.distance) out.band_voxels += std::isfinite(d) ? 1 : 0;

  if (band_only) {
    for (float& d : out.values) d = std::min(d, static_cast<float>(clamp));
  } else if (out.band_voxels < static_cast<std::int64_t>(count)) {
    beyond_band(mesh, box, v, band, out.values, progress);
    progress.throw_if_cancelled();
    if (clamp > 0)
      for (float& d : out.values) d = std::min(d, static_cast<float>(clamp));
  }

  // Step 3: the sign. The surface enters only cells within half a voxel diagonal of it, all in
  // the band.
  if (options.signed_distance) {
    const WindingNumber winding(mesh, options.accuracy);
    std::vector<std::uint8_t> near_surface(count);
    for (std::size_t i = 0; i < count; ++i) near_surface[i] = band.nearest[i] >= 0 ? 1 : 0;
    const std::vector<std::uint8_t> inside =
        detail::inside_voxels(winding, box, v, near_surface, progress);
    progress.throw_if_cancelled();
    for (std::size_t i = 0; i < count; ++i)
      if (inside[i]) out.values[i] = -out.values[i];
  }
  return out;
}

}  // namespace voxfield
