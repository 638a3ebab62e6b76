// voxfield — the Fast Iterative Method (Jeong & Whitaker, "A fast iterative method for eikonal
// equations", SIAM J. Sci. Comput. 2008).
//
// An active list holds the voxels whose value may still fall. One iteration updates every active
// voxel with the local rule of the metric; a voxel whose value no longer changes leaves the list
// and wakes those neighbours it would improve. The local rules:
//   Manhattan  min over the 6 face neighbours of (d + 1)     — converges to the exact L1 field;
//   Chebyshev  min over the 26 neighbours of (d + 1)         — converges to the exact L-inf field;
//   Euclidean  the Godunov upwind solution of |grad d| = 1    — a first-order eikonal solution,
//              not the exact Euclidean distance (its error is what compare reports).
// The dissertation ran the Manhattan rule as full-grid relaxation sweeps "until nothing changes";
// the active list does the same updates without touching settled voxels.
#include <algorithm>
#include <cmath>

#include "dense_problem.h"

namespace voxfield::detail {
namespace {

struct Neighbourhood {
  std::vector<Vec3i> offsets;
};

Neighbourhood neighbourhood(Metric m) {
  Neighbourhood n;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int manhattan = std::abs(dx) + std::abs(dy) + std::abs(dz);
        if (manhattan == 0) continue;
        if (m != Metric::kChebyshev && manhattan != 1) continue;
        n.offsets.push_back({dx, dy, dz});
      }
  return n;
}

class Updater {
 public:
  Updater(const DenseProblem& p, DenseSolution& s) : p_(p), s_(s), hood_(neighbourhood(p.metric)) {}

  const std::vector<Vec3i>& offsets() const { return hood_.offsets; }

  // The local rule at voxel v; `site` receives the site it propagates (L1 / L-inf only).
  float update(const Vec3i v, std::int32_t& site) const {
    if (p_.metric == Metric::kEuclidean) return eikonal(v);
    float best = kFar;
    site = -1;
    for (const Vec3i o : hood_.offsets) {
      const Vec3i q = v + o;
      if (!inside(q)) continue;
      const std::size_t qi = p_.index(q.x, q.y, q.z);
      const float c = s_.d[qi] + 1.0f;
      if (c < best) {
        best = c;
        site = s_.site.empty() ? -1 : s_.site[qi];
      }
    }
    return best;
  }

  bool inside(Vec3i q) const {
    return q.x >= 0 && q.y >= 0 && q.z >= 0 && q.x < p_.n.x && q.y < p_.n.y && q.z < p_.n.z;
  }

 private:
  // Godunov upwind update in 3-D with spacing h: solve sum over the upwind axes of
  // ((u - a_i) / h_i)^2 = 1, using as many axes as keep u above their a_i.
  float eikonal(const Vec3i v) const {
    std::array<std::pair<double, double>, 3> ah;  // (a_i, h_i)
    for (int axis = 0; axis < 3; ++axis) {
      double a = std::numeric_limits<double>::infinity();
      for (int sgn : {-1, 1}) {
        Vec3i q = v;
        q[axis] += sgn;
        if (inside(q)) a = std::min(a, static_cast<double>(s_.d[p_.index(q.x, q.y, q.z)]));
      }
      ah[axis] = {a, p_.spacing[axis]};
    }
    std::sort(ah.begin(), ah.end());
    if (std::isinf(ah[0].first)) return kFar;
    double u = ah[0].first + ah[0].second;
    for (int k = 2; k <= 3; ++k) {
      if (u <= ah[k - 1].first) break;
      // sum_i (u - a_i)^2 / h_i^2 = 1 over the first k axes: A u^2 - 2 B u + C = 0.
      double A = 0, B = 0, C = -1;
      for (int i = 0; i < k; ++i) {
        const double w = 1.0 / (ah[i].second * ah[i].second);
        A += w;
        B += w * ah[i].first;
        C += w * ah[i].first * ah[i].first;
      }
      const double disc = B * B - A * C;
      if (disc < 0) break;
      u = (B + std::sqrt(disc)) / A;
    }
    return static_cast<float>(u);
  }

  const DenseProblem& p_;
  DenseSolution& s_;
  Neighbourhood hood_;
};

}  // namespace

void fast_iterative(const DenseProblem& p, DenseSolution& io, AlgorithmStats& stats,
                    const Box3i& region_in) {
  const Box3i all = Box3i::from_size(p.n);
  const Box3i region = region_in.empty() ? all : region_in.intersect(all);
  const bool fresh = io.d.empty();
  if (fresh) {
    io.d.assign(p.size(), kFar);
    io.site.assign(p.size(), -1);
    for (std::size_t i = 0; i < p.size(); ++i)
      if (p.site[i]) {
        io.d[i] = 0;
        io.site[i] = static_cast<std::int32_t>(i);
      }
  }
  if (p.metric == Metric::kEuclidean) io.site.clear();  // the eikonal rule blends sites
  const float eps = p.metric == Metric::kEuclidean ? 1e-5f : 0.0f;
  Updater up(p, io);
  std::vector<std::uint8_t> active(p.size(), 0);
  std::vector<std::size_t> list, next;
  // Initial list: voxels of the region that their neighbours can improve.
  for (int z = region.begin.z; z < region.end.z; ++z)
    for (int y = region.begin.y; y < region.end.y; ++y)
      for (int x = region.begin.x; x < region.end.x; ++x) {
        const std::size_t i = p.index(x, y, z);
        if (p.site[i]) continue;
        std::int32_t site = -1;
        if (up.update({x, y, z}, site) < io.d[i] - eps) {
          list.push_back(i);
          active[i] = 1;
        }
      }
  while (!list.empty()) {
    if (p.stopped()) return;
    ++stats.iterations;
    next.clear();
    for (const std::size_t i : list) {
      const Vec3i v = p.coord(i);
      const float old = io.d[i];
      std::int32_t site = -1;
      const float u = up.update(v, site);
      ++stats.updates;
      if (u < old) {
        io.d[i] = u;
        if (!io.site.empty()) io.site[i] = site;
      }
      if (old - io.d[i] > eps) {  // still moving: stay active
        next.push_back(i);
        continue;
      }
      active[i] = 0;
      for (const Vec3i o : up.offsets()) {
        const Vec3i q = v + o;
        if (!region.contains(q)) continue;
        const std::size_t qi = p.index(q.x, q.y, q.z);
        if (active[qi] || p.site[qi]) continue;
        std::int32_t qsite = -1;
        const float uq = up.update(q, qsite);
        ++stats.updates;
        if (uq < io.d[qi] - eps) {
          io.d[qi] = uq;
          if (!io.site.empty()) io.site[qi] = qsite;
          active[qi] = 1;
          next.push_back(qi);
        }
      }
    }
    std::swap(list, next);
  }
}

}  // namespace voxfield::detail
