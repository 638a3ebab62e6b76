// voxfield — jump flooding of nearest-site coordinates (Rong & Tan, "Jump flooding in GPU with
// applications to Voronoi diagram and distance transform", I3D 2006), with the correction passes
// of JFA+1 and JFA+2 (Rong & Tan 2007, "Variants of jump flooding algorithm for computing discrete
// Voronoi diagrams").
//
// Each voxel keeps the site it believes nearest; a pass with step k looks at the 26 voxels
// p + k * {-1, 0, 1}^3 and adopts the nearest of their sites. Steps halve from the largest power
// of two below the volume's size down to 1 (log2 N passes). Distances are then exact distances to
// real sites — never too small, sometimes too large where a better site was never offered.
// Ping-pong buffers make every pass read only the previous one, like separate GPU dispatches.
#include <algorithm>

#include "dense_problem.h"
#include "voxfield/parallel.h"

namespace voxfield::detail {
namespace {

void flood_pass(const DenseProblem& p, const std::vector<std::int32_t>& in, std::vector<std::int32_t>& out, int step) {
  parallel_for(static_cast<std::size_t>(p.n.z) * p.n.y, 8, [&](std::size_t r0, std::size_t r1) {
    for (std::size_t r = r0; r < r1; ++r) {
      const int y = static_cast<int>(r % p.n.y), z = static_cast<int>(r / p.n.y);
      for (int x = 0; x < p.n.x; ++x) {
        const std::size_t i = p.index(x, y, z);
        std::int32_t best = in[i];
        double best_d = std::numeric_limits<double>::infinity();
        if (best >= 0) {
          const Vec3i s = p.coord(static_cast<std::size_t>(best));
          best_d = p.distance(s.x - x, s.y - y, s.z - z);
        }
        for (int dz = -1; dz <= 1; ++dz) {
          const int qz = z + dz * step;
          if (qz < 0 || qz >= p.n.z) continue;
          for (int dy = -1; dy <= 1; ++dy) {
            const int qy = y + dy * step;
            if (qy < 0 || qy >= p.n.y) continue;
            for (int dx = -1; dx <= 1; ++dx) {
              const int qx = x + dx * step;
              if (qx < 0 || qx >= p.n.x || (dx == 0 && dy == 0 && dz == 0)) continue;
              const std::int32_t cand = in[p.index(qx, qy, qz)];
              if (cand < 0 || cand == best) continue;
              const Vec3i s = p.coord(static_cast<std::size_t>(cand));
              const double d = p.distance(s.x - x, s.y - y, s.z - z);
              // Ties go to the smaller site index, so the result does not depend on scan order.
              if (d < best_d || (d == best_d && cand < best)) {
                best_d = d;
                best = cand;
              }
            }
          }
        }
        out[i] = best;
      }
    }
  });
}

}  // namespace

void jump_flood(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats, const std::vector<int>& extra_steps) {
  std::vector<std::int32_t> a(p.size()), b(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) a[i] = p.site[i] ? static_cast<std::int32_t>(i) : -1;
  const int largest = std::max({p.n.x, p.n.y, p.n.z});
  std::vector<int> steps;
  int step = 1;
  while (step * 2 < largest) step *= 2;
  for (; step >= 1; step /= 2) steps.push_back(step);
  steps.insert(steps.end(), extra_steps.begin(), extra_steps.end());
  for (int k : steps) {
    flood_pass(p, a, b, k);
    std::swap(a, b);
    ++stats.passes;
    stats.updates += static_cast<std::int64_t>(p.size()) * 27;
  }
  out.d.resize(p.size());
  parallel_for(p.size(), 4096, [&](std::size_t b0, std::size_t b1) {
    for (std::size_t i = b0; i < b1; ++i) out.d[i] = a[i] >= 0 ? static_cast<float>(p.distance(i, static_cast<std::size_t>(a[i]))) : kFar;
  });
  out.site = std::move(a);
}

}  // namespace voxfield::detail
