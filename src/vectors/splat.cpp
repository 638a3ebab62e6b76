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

// Splats every source into the slab out.k0..out.k1 (its arrays clean: -1 and -inf).
void splat_slab(const VectorVolume& v, const CentreTables& centres, std::span<const IndexBox> boxes,
                std::span<const Segment> segments, VectorRule rule, const SlabSplat& out) {
  const int k0 = out.k0, k1 = out.k1;
  const std::int64_t slab_first = v.index(0, 0, k0);
  std::int32_t* winners = out.winners;
  double* best = out.best;
  VectorTexel* texels = out.texels;
  // The box's x column, as the centre tables scale it (a rotation may be orthonormal only to
  // 1e-6, so its length is not taken to be 1).
  const Vec3d axis{v.rotation[0][0], v.rotation[1][0], v.rotation[2][0]};
  const double axis2 = dot(axis, axis);
  const double per_unit = v.resolution.x / v.size.x;  // voxels per unit of `local`
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
        std::int64_t idx = v.index(i0, j, k) - slab_first;
        int won_lo = INT32_MAX, won_hi = -1;
        for (int i = i0; i <= i1; ++i, ++idx) {
          const Vec3d p = base + centres.x[i];
          const double t = segment_t(seg, p);
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
              VectorTexel& texel = texels[idx];
              texel = {};
              if (d > 0) {
                const double inv = 1.0 / d;
                texel.x = static_cast<float>(e.x * inv);
                texel.y = static_cast<float>(e.y * inv);
                texel.z = static_cast<float>(e.z * inv);
              }
              // The strength 1 - d / r is the strongest rule's score, computed once.
              texel.strength =
                  static_cast<float>(rule == VectorRule::kStrongest ? sc : 1.0 - d / seg.radius);
            }
          }
        }
        if (won_hi >= 0) {
          RowSpan& r = out.won[static_cast<std::size_t>(j) +
                               static_cast<std::size_t>(v.resolution.y) * (k - k0)];
          const auto lo = static_cast<std::uint16_t>(won_lo);
          const auto hi = static_cast<std::uint16_t>(won_hi + 1);
          r = r.lo < r.hi ? RowSpan{std::min(r.lo, lo), std::max(r.hi, hi)} : RowSpan{lo, hi};
        }
      }
  }
}

std::vector<IndexBox> boxes_of(const VectorVolume& v, std::span<const VectorSource> sources) {
  std::vector<IndexBox> boxes;
  boxes.reserve(sources.size());
  for (const VectorSource& s : sources) boxes.push_back(index_box(v, s));
  return boxes;
}

}  // namespace

void splat_winners(const VectorVolume& v, std::span<const VectorSource> sources,
                   std::span<const Segment> segments, VectorRule rule, Interrupter* interrupter,
                   std::span<std::int32_t> winners, std::span<double> best) {
  const CentreTables centres(v);
  const std::vector<IndexBox> boxes = boxes_of(v, sources);
  for_each_slab(v, interrupter, "vector field (splat)", [&](int k0, int k1) {
    const auto first = static_cast<std::size_t>(v.index(0, 0, k0));
    splat_slab(v, centres, boxes, segments, rule,
               {k0, k1, winners.data() + first, best.data() + first, nullptr, nullptr});
  });
}

// A slab's arrays, clean between uses: winners -1, best -inf and every row span empty (texels
// are read only where a winner is set).
struct SlabPool::Buffer {
  std::vector<std::int32_t> winners;
  std::vector<double> best;
  std::vector<VectorTexel> texels;
  std::vector<RowSpan> won;
};

SlabPool::SlabPool() = default;
SlabPool::~SlabPool() = default;

std::unique_ptr<SlabPool::Buffer> SlabPool::acquire(const VectorVolume& v, int layers) {
  std::unique_ptr<Buffer> buffer;
  {
    const std::lock_guard lock(mutex_);
    if (!free_.empty()) {
      buffer = std::move(free_.back());
      free_.pop_back();
    }
  }
  if (!buffer) buffer = std::make_unique<Buffer>();
  const std::size_t rows = static_cast<std::size_t>(v.resolution.y) * layers;
  const std::size_t voxels = rows * static_cast<std::size_t>(v.resolution.x);
  if (buffer->winners.size() < voxels) {  // grown clean
    buffer->winners.resize(voxels, -1);
    buffer->best.resize(voxels, kNoScore);
    buffer->texels.resize(voxels);
  }
  if (buffer->won.size() < rows) buffer->won.resize(rows);
  return buffer;
}

void SlabPool::release(std::unique_ptr<Buffer> buffer) {
  const std::lock_guard lock(mutex_);
  free_.push_back(std::move(buffer));
}

void splat_slabs(const VectorVolume& v, std::span<const VectorSource> sources,
                 std::span<const Segment> segments, VectorRule rule, SlabPool& pool,
                 const std::function<void(const SlabSplat&)>& after_slab,
                 std::atomic<std::int64_t>* splat_ns) {
  const CentreTables centres(v);
  const std::vector<IndexBox> boxes = boxes_of(v, sources);
  const int nx = v.resolution.x, ny = v.resolution.y;
  for_each_slab(v, nullptr, "vector field (splat)", [&](int k0, int k1) {
    const std::int64_t slab_start = now_ns();
    // A buffer an exception leaves mid-use is dropped with its unique_ptr, never returned dirty.
    std::unique_ptr<SlabPool::Buffer> buffer = pool.acquire(v, k1 - k0);
    const SlabSplat slab{k0,
                         k1,
                         buffer->winners.data(),
                         buffer->best.data(),
                         buffer->texels.data(),
                         buffer->won.data()};
    splat_slab(v, centres, boxes, segments, rule, slab);
    if (splat_ns) *splat_ns += now_ns() - slab_start;
    after_slab(slab);
    // Only where a source won were winners and scores written.
    const int rows = ny * (k1 - k0);
    for (int row = 0; row < rows; ++row) {
      RowSpan& won = slab.won[row];
      if (won.empty()) continue;
      const std::size_t at = static_cast<std::size_t>(row) * nx + won.lo;
      std::fill_n(slab.winners + at, won.hi - won.lo, -1);
      std::fill_n(slab.best + at, won.hi - won.lo, kNoScore);
      won = {};
    }
    pool.release(std::move(buffer));
  });
}

}  // namespace voxfield::detail::vectors
