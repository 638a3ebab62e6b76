// Jump flooding (Rong & Tan, "Jump flooding in GPU with applications to Voronoi diagram and
// distance transform", I3D 2006) and its variants JFA+1 and JFA+2 (Rong & Tan, "Variants of jump
// flooding algorithm for computing discrete Voronoi diagrams", ISVD 2007), as the paper's GPU
// path used them, without its defects:
//  * seeding marks every voxel a source touches — the voxel of each point along its segment, at
//    steps of half a voxel, so a source smaller than a voxel still seeds the voxel it is in and a
//    fast mover seeds its whole trail; a point outside the box seeds the voxel nearest to it when
//    the source can reach the box at all. Two sources in one voxel: the better score at the
//    voxel's centre keeps it (ties: the lower index), decided in index order, not by a race;
//  * each pass of step s (N/2, ..., 1; then 1 for JFA+1, 2 and 1 for JFA+2) reads one buffer and
//    writes the other (ping-pong, never in place): a voxel takes the best of its own source and
//    those of its 26 neighbours at offsets of s;
//  * the conversion pass (write_vector_texels) computes the exact direction and strength from the
//    source each voxel settled on, and writes zero where it does not cover the voxel.
// JFA is not exact: compare_vector_winners reports how far it lands from the definition.
#include <cmath>

#include "vector_internal.h"

namespace voxfield::detail::vectors {
namespace {

// Keeps whichever of `current` and `candidate` scores better at p (ties: the lower index).
inline void consider(std::span<const Segment> segments, VectorRule rule, Vec3d p,
                     std::int32_t candidate, std::int32_t& current, double& current_score) {
  if (candidate < 0 || candidate == current) return;
  Vec3d q;
  const Segment& s = segments[static_cast<std::size_t>(candidate)];
  const double sc = score(rule, distance_to(s, p, q), s.radius);
  if (current < 0 || sc > current_score || (sc == current_score && candidate < current)) {
    current = candidate;
    current_score = sc;
  }
}

void seed(const VectorVolume& v, std::span<const VectorSource> sources,
          std::span<const Segment> segments, VectorRule rule, const CentreTables& centres,
          std::span<std::int32_t> out) {
  const Vec3i n = v.resolution;
  std::vector<double> seeded_score(out.size(), 0);
  for (std::size_t s = 0; s < sources.size(); ++s) {
    const SeedSpan span = seed_span(v, sources[s], segments[s]);
    for (int t = 0; t <= span.samples; ++t) {
      const double along = span.t0 + (span.t1 - span.t0) * (static_cast<double>(t) / span.samples);
      const Vec3d point = segments[s].a + segments[s].ab * along;
      const Vec3d u = v.to_volume(point);
      int idx[3];
      for (int a = 0; a < 3; ++a)
        idx[a] = static_cast<int>(std::clamp(std::floor(u[a] * n[a]), 0.0, n[a] - 1.0));
      const std::size_t at = static_cast<std::size_t>(v.index(idx[0], idx[1], idx[2]));
      std::int32_t current = out[at];
      double current_score = seeded_score[at];
      consider(segments, rule, centres.at(idx[0], idx[1], idx[2]), static_cast<std::int32_t>(s),
               current, current_score);
      out[at] = current;
      seeded_score[at] = current_score;
    }
  }
}

void flood_pass(const VectorVolume& v, std::span<const Segment> segments, VectorRule rule,
                const CentreTables& centres, int step, Interrupter* interrupter,
                std::span<const std::int32_t> in, std::span<std::int32_t> out) {
  const Vec3i n = v.resolution;
  for_each_slab(v, interrupter, "vector field (jump flooding)", [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k)
      for (int j = 0; j < n.y; ++j)
        for (int i = 0; i < n.x; ++i) {
          const Vec3d p = centres.at(i, j, k);
          std::int32_t best = in[static_cast<std::size_t>(v.index(i, j, k))];
          double best_score = 0;
          if (best >= 0) {
            Vec3d q;
            const Segment& s = segments[static_cast<std::size_t>(best)];
            best_score = score(rule, distance_to(s, p, q), s.radius);
          }
          for (int dz = -step; dz <= step; dz += step) {
            const int kk = k + dz;
            if (kk < 0 || kk >= n.z) continue;
            for (int dy = -step; dy <= step; dy += step) {
              const int jj = j + dy;
              if (jj < 0 || jj >= n.y) continue;
              for (int dx = -step; dx <= step; dx += step) {
                const int ii = i + dx;
                if (ii < 0 || ii >= n.x || (dx == 0 && dy == 0 && dz == 0)) continue;
                consider(segments, rule, p, in[static_cast<std::size_t>(v.index(ii, jj, kk))], best,
                         best_score);
              }
            }
          }
          out[static_cast<std::size_t>(v.index(i, j, k))] = best;
        }
  });
}

}  // namespace

SeedSpan seed_span(const VectorVolume& v, const VectorSource& source, const Segment& segment) {
  if (index_box(v, source).empty()) return {};  // cannot reach any voxel centre
  // Only the part of the segment within the radius of the box can seed a voxel that matters:
  // clip it to the box grown by r (slab test in volume coordinates), so a long trail far
  // outside costs nothing and the samples stay half a voxel apart.
  const Vec3d ua = v.to_volume(segment.a), ub = v.to_volume(segment.a + segment.ab);
  double t0 = 0, t1 = 1;
  for (int a = 0; a < 3; ++a) {
    const double grow = segment.radius / v.size[a], d = ub[a] - ua[a];
    const double lo = -grow, hi = 1 + grow;
    if (d == 0) {
      if (ua[a] < lo || ua[a] > hi) t1 = -1;
      continue;
    }
    double ta = (lo - ua[a]) / d, tb = (hi - ua[a]) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) {  // the segment misses the grown box: seed its point nearest to the box
    t0 = t1 = std::clamp(t0, 0.0, 1.0);
  }
  const Vec3d vs = v.voxel_size();
  const double half_voxel = 0.5 * std::min({vs.x, vs.y, vs.z});
  const double length = std::sqrt(segment.ab2) * (t1 - t0);
  // Within the grown box a segment is at most its diagonal long: this many samples is bounded.
  return {t0, t1, 1 + static_cast<int>(std::ceil(length / half_voxel))};
}

std::vector<int> jfa_steps(const VectorVolume& v, int extra_passes) {
  std::vector<int> steps;
  const int longest = std::max({v.resolution.x, v.resolution.y, v.resolution.z});
  if (longest == 1) return steps;  // one voxel across: nothing to flood
  int first = 1;
  while (first * 2 < longest) first *= 2;  // N/2 for a power of two N; the same rounding up
  for (int s = first; s >= 1; s /= 2) steps.push_back(s);
  if (extra_passes >= 2) steps.push_back(2);
  if (extra_passes >= 1) steps.push_back(1);
  return steps;
}

void jfa_winners(const VectorVolume& v, std::span<const VectorSource> sources,
                 std::span<const Segment> segments, VectorRule rule, int extra_passes,
                 Interrupter* interrupter, std::span<std::int32_t> winners,
                 VectorPassTimes* times) {
  const CentreTables centres(v);
  std::int64_t start = now_ns();
  seed(v, sources, segments, rule, centres, winners);
  times->seed_ms += ms_since(start);

  start = now_ns();
  const std::vector<int> steps = jfa_steps(v, extra_passes);
  std::vector<std::int32_t> other(winners.size(), -1);
  std::span<std::int32_t> a = winners, b = other;
  for (int s : steps) {
    flood_pass(v, segments, rule, centres, s, interrupter, a, b);
    std::swap(a, b);
    ++times->flood_passes;
  }
  if (a.data() != winners.data()) std::copy(a.begin(), a.end(), winners.begin());
  times->flood_ms += ms_since(start);
}

}  // namespace voxfield::detail::vectors
