// Splatting: each source visits only the voxels of its own bounding box (its capsule's box in the
// volume's frame, index_box), and each voxel keeps the best score seen so far. Exact — the same
// winners as brute force, bit for bit — at a cost proportional to the volume the sources cover
// rather than voxels x sources. The default algorithm.
//
// Sources are visited in index order and a voxel changes hands only on a strictly better score,
// so ties go to the lower index as the definition says; the volume is cut into z slabs, one
// thread each, so no two threads write one voxel and the result does not depend on the threads.
#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>

#include "vector_internal.h"

namespace voxfield::detail::vectors {

namespace {
constexpr double kNoScore = -std::numeric_limits<double>::infinity();
}

void SplatScratch::prepare(const VectorVolume& v) {
  const std::size_t n = static_cast<std::size_t>(v.voxel_count());
  if (winners.size() == n && best.size() == n && texels.size() == (keep_texels ? n : 0)) return;
  // (won follows texels: both are sized here whenever keep_texels is set)
  // Built aside and swapped in: a failed allocation leaves the scratch as it was.
  std::vector<std::int32_t> w(n, -1);
  std::vector<double> b(n, kNoScore);
  std::vector<VectorTexel> t(keep_texels ? n : 0);
  std::vector<RowSpan> r(keep_texels ? static_cast<std::size_t>(v.resolution.y) * v.resolution.z
                                     : 0);
  winners.swap(w);
  best.swap(b);
  texels.swap(t);
  won.swap(r);
  boxes.clear();
}

void SplatScratch::reset(const VectorVolume& v, std::span<const IndexBox> last, int k0, int k1) {
  for (const IndexBox& b : last) {
    if (b.empty()) continue;
    for (int k = std::max(b.lo[2], k0); k <= std::min(b.hi[2], k1 - 1); ++k)
      for (int j = b.lo[1]; j <= b.hi[1]; ++j) {
        const std::size_t at = static_cast<std::size_t>(v.index(b.lo[0], j, k));
        const std::size_t count = static_cast<std::size_t>(b.hi[0] - b.lo[0] + 1);
        std::fill_n(winners.begin() + static_cast<std::ptrdiff_t>(at), count, -1);
        std::fill_n(best.begin() + static_cast<std::ptrdiff_t>(at), count, kNoScore);
      }
  }
}

void splat_winners(const VectorVolume& v, std::span<const VectorSource> sources,
                   std::span<const Segment> segments, VectorRule rule, Interrupter* interrupter,
                   SplatScratch& scratch, const std::function<void(int, int)>& after_slab,
                   std::atomic<std::int64_t>* splat_ns) {
  scratch.prepare(v);
  const CentreTables centres(v);
  // The last splat's boxes are cleared slab by slab, in parallel, just before each slab splats.
  // Until this splat completes the scratch names both sets of boxes, so whatever a cancellation
  // leaves behind, the next splat clears it.
  const std::size_t last_count = scratch.boxes.size();
  for (const VectorSource& s : sources) scratch.boxes.push_back(index_box(v, s));
  const std::span<const IndexBox> last(scratch.boxes.data(), last_count);
  const std::span<const IndexBox> boxes(scratch.boxes.data() + last_count, sources.size());
  std::int32_t* winners = scratch.winners.data();
  double* best = scratch.best.data();
  VectorTexel* texels = scratch.keep_texels ? scratch.texels.data() : nullptr;
  RowSpan* won = texels ? scratch.won.data() : nullptr;
  for_each_slab(v, interrupter, "vector field (splat)", [&](int k0, int k1) {
    const std::int64_t slab_start = now_ns();
    scratch.reset(v, last, k0, k1);
    if (won)
      std::fill(won + static_cast<std::ptrdiff_t>(k0) * v.resolution.y,
                won + static_cast<std::ptrdiff_t>(k1) * v.resolution.y, RowSpan{});
    for (std::size_t s = 0; s < segments.size(); ++s) {
      const IndexBox& b = boxes[s];
      if (b.empty() || b.hi[2] < k0 || b.lo[2] >= k1) continue;
      const Segment& seg = segments[s];
      // A squared-distance test first, loose by a relative 1e-9 so that it only skips voxels
      // certainly outside: the exact test (d < r after the square root, as the definition)
      // decides the rest, so the winners stay bit for bit those of brute force.
      const double reject2 = seg.radius * seg.radius * (1 + 1e-9);
      // The capsule lies inside the sphere about its segment's midpoint of radius r + |ab| / 2,
      // which meets each row of the box in an interval: only that interval (widened by a voxel
      // each side against rounding) is visited, so a source costs about its sphere, not its box.
      const Vec3d mid = seg.a + seg.ab * 0.5;
      const double bound = seg.radius + 0.5 * std::sqrt(seg.ab2);
      // The box's x column, as the centre tables scale it (a rotation may be orthonormal only to
      // 1e-6, so its length is not taken to be 1).
      const Vec3d axis{v.rotation[0][0], v.rotation[1][0], v.rotation[2][0]};
      const double axis2 = dot(axis, axis);
      const double per_unit = v.resolution.x / v.size.x;  // voxels per unit of `local`
      for (int k = std::max(b.lo[2], k0); k <= std::min(b.hi[2], k1 - 1); ++k)
        for (int j = b.lo[1]; j <= b.hi[1]; ++j) {
          const Vec3d base = centres.row(j, k);
          // The row is base + axis * local: the sphere's chord on it, in voxel indices. The
          // perpendicular part is computed as a vector (not |to_mid|^2 - along^2, which cancels),
          // and the bound is loosened by the rounding of these sums, relative to their size.
          const Vec3d to_mid = mid - base;
          const double closest = dot(to_mid, axis) / axis2;  // `local` nearest to the midpoint
          const Vec3d perp = to_mid - axis * closest;
          const double off2 = dot(perp, perp);
          const double bound2 = bound * bound * (1 + 1e-9) + 1e-12 * dot(to_mid, to_mid);
          if (off2 > bound2) continue;
          const double half = std::sqrt((bound2 - off2) / axis2);
          const double first = (closest - half) * per_unit + 0.5 * v.resolution.x - 0.5;
          const double last = (closest + half) * per_unit + 0.5 * v.resolution.x - 0.5;
          const int i0 = std::max(b.lo[0], static_cast<int>(std::max(-1.0, std::floor(first)) - 1));
          const int i1 = std::min(
              b.hi[0],
              static_cast<int>(std::min(static_cast<double>(v.resolution.x), std::ceil(last)) + 1));
          std::int64_t idx = v.index(i0, j, k);
          int won_lo = INT32_MAX, won_hi = -1;
          for (int i = i0; i <= i1; ++i, ++idx) {
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
              if (texels) {  // as texel_of(value_of(...)): e is p - q, the same doubles
                won_lo = std::min(won_lo, i);
                won_hi = i;
                VectorTexel& out = texels[idx];
                out = {};
                if (d > 0) {
                  const double inv = 1.0 / d;
                  out.x = static_cast<float>(e.x * inv);
                  out.y = static_cast<float>(e.y * inv);
                  out.z = static_cast<float>(e.z * inv);
                }
                // The strength 1 - d / r is the strongest rule's score, computed once.
                out.strength =
                    static_cast<float>(rule == VectorRule::kStrongest ? sc : 1.0 - d / seg.radius);
              }
            }
          }
          if (won_hi >= 0) {  // rows are split between slabs, never between threads
            RowSpan& r =
                won[static_cast<std::size_t>(j) + static_cast<std::size_t>(v.resolution.y) * k];
            const auto lo = static_cast<std::uint16_t>(won_lo);
            const auto hi = static_cast<std::uint16_t>(won_hi + 1);
            r = r.lo < r.hi ? RowSpan{std::min(r.lo, lo), std::max(r.hi, hi)} : RowSpan{lo, hi};
          }
        }
    }
    if (splat_ns) *splat_ns += now_ns() - slab_start;
    if (after_slab) after_slab(k0, k1);
  });
  scratch.boxes.erase(scratch.boxes.begin(),
                      scratch.boxes.begin() + static_cast<std::ptrdiff_t>(last_count));
}

}  // namespace voxfield::detail::vectors
