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
#include <tuple>

#include "dense_problem.h"
#include "voxfield/parallel.h"

namespace voxfield::detail {
namespace {

// Coordinates rather than indices keep the 27 candidate distances of a pass free of divisions.
using Site = JfaSite;

// Comparable distance of an offset: exact integers for unit spacing (squared for Euclidean).
struct UnitCost {
  Metric m;
  std::int64_t operator()(int dx, int dy, int dz) const {
    dx = std::abs(dx), dy = std::abs(dy), dz = std::abs(dz);
    switch (m) {
      case Metric::kManhattan:
        return dx + dy + dz;
      case Metric::kChebyshev:
        return std::max({dx, dy, dz});
      case Metric::kEuclidean:
        return std::int64_t{dx} * dx + std::int64_t{dy} * dy + std::int64_t{dz} * dz;
    }
    return 0;
  }
};

struct SpacedCost {
  const DenseProblem* p;
  double operator()(int dx, int dy, int dz) const { return p->distance(dx, dy, dz); }
};

template <class Cost>
void flood_pass(const DenseProblem& p, const Cost& cost, const std::vector<Site>& in,
                std::vector<Site>& out, int step) {
  using C = decltype(cost(0, 0, 0));
  parallel_for(static_cast<std::size_t>(p.n.z) * p.n.y, 8, [&](std::size_t r0, std::size_t r1) {
    for (std::size_t r = r0; r < r1; ++r) {
      const int y = static_cast<int>(r % p.n.y), z = static_cast<int>(r / p.n.y);
      for (int x = 0; x < p.n.x; ++x) {
        const std::size_t i = p.index(x, y, z);
        Site best = in[i];
        C best_c =
            best.x >= 0 ? cost(best.x - x, best.y - y, best.z - z) : std::numeric_limits<C>::max();
        for (int dz = -1; dz <= 1; ++dz) {
          const int qz = z + dz * step;
          if (qz < 0 || qz >= p.n.z) continue;
          for (int dy = -1; dy <= 1; ++dy) {
            const int qy = y + dy * step;
            if (qy < 0 || qy >= p.n.y) continue;
            const std::size_t row = p.index(0, qy, qz);
            for (int dx = -1; dx <= 1; ++dx) {
              const int qx = x + dx * step;
              if (qx < 0 || qx >= p.n.x) continue;
              const Site s = in[row + static_cast<std::size_t>(qx)];
              if (s.x < 0) continue;
              const C c = cost(s.x - x, s.y - y, s.z - z);
              // Ties go to the smaller (z, y, x), so the result does not depend on scan order.
              if (c < best_c ||
                  (c == best_c && std::tie(s.z, s.y, s.x) < std::tie(best.z, best.y, best.x))) {
                best_c = c;
                best = s;
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

std::vector<JfaSite> jfa_seeds(const DenseProblem& p) {
  std::vector<JfaSite> a(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p.site[i]) continue;
    const Vec3i c = p.coord(i);
    a[i] = {static_cast<std::int16_t>(c.x), static_cast<std::int16_t>(c.y),
            static_cast<std::int16_t>(c.z)};
  }
  return a;
}

std::vector<int> jfa_steps(const DenseProblem& p, const std::vector<int>& extra_steps) {
  if (std::max({p.n.x, p.n.y, p.n.z}) > 32767)
    throw InvalidArgument("jump flooding supports domains up to 32767 voxels per axis");
  const int largest = std::max({p.n.x, p.n.y, p.n.z});
  std::vector<int> steps;
  int step = 1;
  while (step * 2 < largest) step *= 2;
  for (; step >= 1; step /= 2) steps.push_back(step);
  steps.insert(steps.end(), extra_steps.begin(), extra_steps.end());
  return steps;
}

void jfa_solution(const DenseProblem& p, const std::vector<JfaSite>& sites, DenseSolution& out) {
  out.d.resize(p.size());
  out.site.resize(p.size());
  parallel_for(p.size(), 4096, [&](std::size_t b0, std::size_t b1) {
    for (std::size_t i = b0; i < b1; ++i) {
      const JfaSite s = sites[i];
      if (s.x < 0) {
        out.d[i] = kFar;
        out.site[i] = -1;
        continue;
      }
      const Vec3i c = p.coord(i);
      out.d[i] = static_cast<float>(p.distance(s.x - c.x, s.y - c.y, s.z - c.z));
      out.site[i] = static_cast<std::int32_t>(p.index(s.x, s.y, s.z));
    }
  });
}

void jump_flood(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats,
                const std::vector<int>& extra_steps) {
  const std::vector<int> steps = jfa_steps(p, extra_steps);
  std::vector<Site> a = jfa_seeds(p), b(p.size());
  const bool unit = p.spacing == std::array<double, 3>{1, 1, 1};
  for (int k : steps) {
    if (p.stopped()) return;
    if (unit) {
      flood_pass(p, UnitCost{p.metric}, a, b, k);
    } else {
      flood_pass(p, SpacedCost{&p}, a, b, k);
    }
    std::swap(a, b);
    ++stats.passes;
    stats.updates += static_cast<std::int64_t>(p.size()) * 27;
  }
  jfa_solution(p, a, out);
}

}  // namespace voxfield::detail
