// voxfield-mpi bench: a world of random solid spheres generated slab by slab, so that no rank ever
// holds more than its own slab (the spheres are drawn from one seed, the same on every rank).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "voxfield/world.h"

namespace voxfield::mpi_bench {

struct Sphere {
  double x, y, z, r;
};

inline std::vector<Sphere> random_spheres(const Box3i& domain, int count) {
  std::mt19937_64 rng(20261202);
  const Vec3i s = domain.size();
  const double r_max = std::max(2.0, std::min({s.x, s.y, s.z}) / 10.0);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<Sphere> out(static_cast<std::size_t>(count));
  for (Sphere& p : out)
    p = {domain.begin.x + u(rng) * s.x, domain.begin.y + u(rng) * s.y,
         domain.begin.z + u(rng) * s.z, 1 + u(rng) * (r_max - 1)};
  return out;
}

// The voxels of `slab` (material 1 inside a sphere): one slice at a time, row spans filled.
inline World sphere_world_slab(const Box3i& domain, const Box3i& slab, int count, int chunk_edge) {
  const std::vector<Sphere> spheres = random_spheres(domain, count);
  World w(chunk_edge, slab);
  const int X = slab.size().x, Y = slab.size().y;
  std::vector<std::uint8_t> slice(static_cast<std::size_t>(X) * static_cast<std::size_t>(Y));
  for (int z = slab.begin.z; z < slab.end.z; ++z) {
    std::fill(slice.begin(), slice.end(), 0);
    bool any = false;
    for (const Sphere& s : spheres) {
      const double dz = z + 0.5 - s.z;
      if (std::abs(dz) >= s.r) continue;
      const double rz = std::sqrt(s.r * s.r - dz * dz);
      const int y0 = std::max(slab.begin.y, static_cast<int>(std::ceil(s.y - rz - 0.5)));
      const int y1 = std::min(slab.end.y - 1, static_cast<int>(std::floor(s.y + rz - 0.5)));
      for (int y = y0; y <= y1; ++y) {
        const double dy = y + 0.5 - s.y;
        const double h = rz * rz - dy * dy;
        if (h < 0) continue;
        const double rx = std::sqrt(h);
        const int x0 = std::max(slab.begin.x, static_cast<int>(std::ceil(s.x - rx - 0.5)));
        const int x1 = std::min(slab.end.x - 1, static_cast<int>(std::floor(s.x + rx - 0.5)));
        if (x0 > x1) continue;
        std::memset(
            slice.data() + static_cast<std::size_t>(y - slab.begin.y) * X + (x0 - slab.begin.x), 1,
            static_cast<std::size_t>(x1 - x0 + 1));
        any = true;
      }
    }
    if (any)
      w.voxels.copy_from_dense({{slab.begin.x, slab.begin.y, z}, {slab.end.x, slab.end.y, z + 1}},
                               slice.data());
  }
  return w;
}

}  // namespace voxfield::mpi_bench
