// voxfield — brute force: every voxel scans every site. The dissertation's baseline (and the
// definition of the exact transform); O(voxels x sites), so it refuses large inputs.
#include <cstdio>
#include <string>

#include "dense_problem.h"
#include "voxfield/parallel.h"

namespace voxfield::detail {

void brute_force(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats,
                 double max_work) {
  std::vector<std::int32_t> sites;
  for (std::size_t i = 0; i < p.size(); ++i)
    if (p.site[i]) sites.push_back(static_cast<std::int32_t>(i));
  const double work = static_cast<double>(p.size()) * static_cast<double>(sites.size());
  if (work > max_work) {
    char text[160];
    std::snprintf(
        text, sizeof text,
        "brute force would need %.3g distance evaluations (limit %.3g); use a smaller input", work,
        max_work);
    throw InvalidArgument(text);
  }
  std::vector<Vec3i> site_xyz(sites.size());
  for (std::size_t k = 0; k < sites.size(); ++k)
    site_xyz[k] = p.coord(static_cast<std::size_t>(sites[k]));
  out.d.assign(p.size(), kFar);
  out.site.assign(p.size(), -1);
  parallel_for(p.size(), 256, [&](std::size_t b, std::size_t e) {
    if (p.stopped()) return;
    for (std::size_t i = b; i < e; ++i) {
      if (p.site[i]) {
        out.d[i] = 0;
        out.site[i] = static_cast<std::int32_t>(i);
        continue;
      }
      const Vec3i v = p.coord(i);
      double best = std::numeric_limits<double>::infinity();
      std::int32_t arg = -1;
      for (std::size_t k = 0; k < sites.size(); ++k) {
        const double d = p.distance(site_xyz[k].x - v.x, site_xyz[k].y - v.y, site_xyz[k].z - v.z);
        if (d < best) {
          best = d;
          arg = sites[k];
        }
      }
      out.d[i] = static_cast<float>(best);
      out.site[i] = arg;
    }
  });
  stats.updates += static_cast<std::int64_t>(work);
  stats.passes = 1;
}

}  // namespace voxfield::detail
