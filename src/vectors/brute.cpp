// The paper's brute-force algorithm (BFA; Hamlin, "Volumetric Interaction", section 3): every voxel
// tests every source. Exact: its winners are the definition's (vector_at), bit for bit. Its cost
// is voxels x sources, whatever the sources' size; splat.cpp does the same work in proportion to
// the volume the sources cover.
#include "vector_internal.h"

namespace voxfield::detail::vectors {

void brute_winners(const VectorVolume& v, std::span<const Segment> sources, VectorRule rule,
                   Interrupter* interrupter, std::span<std::int32_t> winners) {
  const CentreTables centres(v);
  const Vec3i n = v.resolution;
  for_each_slab(v, interrupter, "vector field (brute force)", [&](int k0, int k1) {
    for (int k = k0; k < k1; ++k)
      for (int j = 0; j < n.y; ++j) {
        std::int64_t idx = v.index(0, j, k);
        for (int i = 0; i < n.x; ++i, ++idx) {
          const Vec3d p = centres.at(i, j, k);
          std::int32_t best = -1;
          double best_score = 0;
          for (std::size_t s = 0; s < sources.size(); ++s) {
            Vec3d q;
            const double d = distance_to(sources[s], p, q);
            if (!(d < sources[s].radius)) continue;
            const double sc = score(rule, d, sources[s].radius);
            if (best < 0 || sc > best_score) {
              best = static_cast<std::int32_t>(s);
              best_score = sc;
            }
          }
          winners[static_cast<std::size_t>(idx)] = best;
        }
      }
  });
}

}  // namespace voxfield::detail::vectors
