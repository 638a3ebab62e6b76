// Splatting: each source visits only the voxels of its own bounding box (its capsule's box in the
// volume's frame, index_box), and each voxel keeps the best score seen so far. Exact — the same
// winners as brute force, bit for bit — at a cost proportional to the volume the sources cover
// rather than voxels x sources. The default algorithm.
//
// Sources are visited in index order and a voxel changes hands only on a strictly better score,
// so ties go to the lower index as the definition says; the volume is cut into z slabs, one
// thread each, so no two threads write one voxel and the result does not depend on the threads.
#include <limits>

#include "vector_internal.h"

namespace voxfield::detail::vectors {

namespace {
constexpr double kNoScore = -std::numeric_limits<double>::infinity();
}

void SplatScratch::prepare(const VectorVolume& v) {
  const std::size_t n = static_cast<std::size_t>(v.voxel_count());
  if (winners.size() == n && best.size() == n) return;
  // Built aside and swapped in: a failed allocation leaves the scratch as it was.
  std::vector<std::int32_t> w(n, -1);
  std::vector<double> b(n, kNoScore);
  winners.swap(w);
  best.swap(b);
  boxes.clear();
}

void SplatScratch::reset(const VectorVolume& v) {
  for (const IndexBox& b : boxes) {
    if (b.empty()) continue;
    for (int k = b.lo[2]; k <= b.hi[2]; ++k)
      for (int j = b.lo[1]; j <= b.hi[1]; ++j) {
        const std::size_t at = static_cast<std::size_t>(v.index(b.lo[0], j, k));
        const std::size_t count = static_cast<std::size_t>(b.hi[0] - b.lo[0] + 1);
        std::fill_n(winners.begin() + static_cast<std::ptrdiff_t>(at), count, -1);
        std::fill_n(best.begin() + static_cast<std::ptrdiff_t>(at), count, kNoScore);
      }
  }
  boxes.clear();
}

void splat_winners(const VectorVolume& v, std::span<const VectorSource> sources,
                   std::span<const Segment> segments, VectorRule rule, Interrupter* interrupter,
                   SplatScratch& scratch) {
  scratch.prepare(v);
  scratch.reset(v);
  const CentreTables centres(v);
  for (const VectorSource& s : sources) scratch.boxes.push_back(index_box(v, s));
  std::int32_t* winners = scratch.winners.data();
  double* best = scratch.best.data();
  for_each_slab(v, interrupter, "vector field (splat)", [&](int k0, int k1) {
    for (std::size_t s = 0; s < segments.size(); ++s) {
      const IndexBox& b = scratch.boxes[s];
      if (b.empty() || b.hi[2] < k0 || b.lo[2] >= k1) continue;
      const Segment& seg = segments[s];
      // A squared-distance test first, loose by a relative 1e-9 so that it only skips voxels
      // certainly outside: the exact test (d < r after the square root, as the definition) decides
      // the rest, so the winners stay bit for bit those of brute force.
      const double reject2 = seg.radius * seg.radius * (1 + 1e-9);
      for (int k = std::max(b.lo[2], k0); k <= std::min(b.hi[2], k1 - 1); ++k)
        for (int j = b.lo[1]; j <= b.hi[1]; ++j) {
          const Vec3d base = centres.row(j, k);
          std::int64_t idx = v.index(b.lo[0], j, k);
          for (int i = b.lo[0]; i <= b.hi[0]; ++i, ++idx) {
            const Vec3d p = base + centres.x[i];
            double t = 0;
            if (seg.ab2 > 0) t = std::clamp(dot(p - seg.a, seg.ab) / seg.ab2, 0.0, 1.0);
            const Vec3d e = p - (seg.a + seg.ab * t);
            const double e2 = dot(e, e);
            if (e2 > reject2) continue;
            const double d = std::sqrt(e2);
            if (!(d < seg.radius)) continue;
            const double sc = score(rule, d, seg.radius);
            if (sc > best[idx]) {
              best[idx] = sc;
              winners[idx] = static_cast<std::int32_t>(s);
            }
          }
        }
    }
  });
}

}  // namespace voxfield::detail::vectors
