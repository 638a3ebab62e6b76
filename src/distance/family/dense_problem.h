// voxfield — the dense form in which the dissertation's algorithms work (internal).
//
// The algorithm family is reproduced for measurement, the way the dissertation ran it on the GPU:
// on a dense array over the domain. A problem is the set of site voxels; a solution is, per
// voxel, a distance (+inf when unknown) and, where the algorithm tracks it, the index of the site
// it stands for (-1 when none).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "voxfield/algorithms.h"
#include "voxfield/interrupt.h"

namespace voxfield::detail {

inline constexpr float kFar = std::numeric_limits<float>::infinity();

struct DenseProblem {
  Box3i box;                       // the domain
  Vec3i n;                         // its size
  std::vector<std::uint8_t> site;  // 1 where the voxel is a site
  Metric metric = Metric::kManhattan;
  std::array<double, 3> spacing{1, 1, 1};
  int chunk_edge = 32;  // of the world, for the chunked algorithms
  // Asked between passes (and blocks of work) whether to go on; null when nobody watches. A
  // solver that is told to stop returns early, and the caller throws Cancelled.
  Progress* progress = nullptr;
  bool stopped() const { return progress && !progress->keep_going(); }

  std::size_t size() const { return site.size(); }
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * n.y + y) * n.x + x;
  }
  Vec3i coord(std::size_t i) const {
    const std::size_t nx = static_cast<std::size_t>(n.x), nxy = nx * static_cast<std::size_t>(n.y);
    return {static_cast<int>(i % nx), static_cast<int>((i / nx) % n.y), static_cast<int>(i / nxy)};
  }
  // Distance between voxel centres offset by (dx, dy, dz) voxels, in the problem's metric.
  double distance(int dx, int dy, int dz) const {
    const double ax = std::abs(dx) * spacing[0], ay = std::abs(dy) * spacing[1],
                 az = std::abs(dz) * spacing[2];
    switch (metric) {
      case Metric::kManhattan:
        return ax + ay + az;
      case Metric::kChebyshev:
        return std::max({ax, ay, az});
      case Metric::kEuclidean:
        return std::sqrt(ax * ax + ay * ay + az * az);
    }
    return 0;
  }
  double distance(std::size_t a, std::size_t b) const {
    const Vec3i p = coord(a), q = coord(b);
    return distance(q.x - p.x, q.y - p.y, q.z - p.z);
  }
};

struct DenseSolution {
  std::vector<float> d;            // distance per voxel
  std::vector<std::int32_t> site;  // nearest-site index per voxel, or -1 (empty if not tracked)
};

// The algorithms. Each fills `out` for `p` and adds to `stats`.
void brute_force(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats, double max_work);
void brute_chunked(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats);
void jump_flood_seed(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats);
// extra_steps: the steps of the correction passes after the standard ones ({}, {1} or {2, 1}).
void jump_flood(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats,
                const std::vector<int>& extra_steps);

// Jump flooding's pieces, shared with the GPU backend (which runs the passes itself).
// A voxel's current nearest site, as coordinates in the domain (x < 0: none).
struct JfaSite {
  std::int16_t x = -1, y = -1, z = -1;
};
// The sites before the first pass: each site voxel is its own.
std::vector<JfaSite> jfa_seeds(const DenseProblem& p);
// The pass steps: halving from the largest power of two below the largest extent down to 1,
// then extra_steps. Throws InvalidArgument for extents beyond 32767.
std::vector<int> jfa_steps(const DenseProblem& p, const std::vector<int>& extra_steps);
// Distances (and site indices) from the final sites.
void jfa_solution(const DenseProblem& p, const std::vector<JfaSite>& sites, DenseSolution& out);
// Refines `io` (initially +inf except 0 at sites, or an upper bound such as a JFA result) by the
// Fast Iterative Method. Only voxels inside `region` (all when empty) are updated.
void fast_iterative(const DenseProblem& p, DenseSolution& io, AlgorithmStats& stats,
                    const Box3i& region);

}  // namespace voxfield::detail
