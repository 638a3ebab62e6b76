// voxfield — chunked brute force, as the dissertation ran it: each chunk is solved on its own,
// with a one-voxel border around it treated as solid so that the chunk needs no neighbours.
//
// The padding is what makes it wrong: a voxel's distance can never exceed its distance to the
// chunk border plus one, so fields are capped near every chunk face (too small, never too large).
// Each padded chunk is solved with the exact separable transform, which gives exactly the per-chunk
// brute-force result at a fraction of its cost.
#include <algorithm>

#include "dense_problem.h"
#include "voxfield/distance.h"
#include "voxfield/parallel.h"

namespace voxfield::detail {

void brute_chunked(const DenseProblem& p, DenseSolution& out, AlgorithmStats& stats) {
  const int e = p.chunk_edge;
  out.d.assign(p.size(), kFar);
  out.site.assign(p.size(), -1);
  // Chunks are aligned to the world's chunk grid, as the dissertation's were.
  auto floor_div = [](int a, int b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  const Vec3i c0{floor_div(p.box.begin.x, e), floor_div(p.box.begin.y, e),
                 floor_div(p.box.begin.z, e)};
  const Vec3i c1{floor_div(p.box.end.x - 1, e), floor_div(p.box.end.y - 1, e),
                 floor_div(p.box.end.z - 1, e)};
  std::vector<Vec3i> chunks;
  for (int z = c0.z; z <= c1.z; ++z)
    for (int y = c0.y; y <= c1.y; ++y)
      for (int x = c0.x; x <= c1.x; ++x) chunks.push_back({x, y, z});
  // The padded chunk (edge + 2) fits a grid chunk of twice the edge (at most 256 > 128: use 128).
  const int inner_edge = std::min(128, 2 * e);
  parallel_for(chunks.size(), 1, [&](std::size_t b, std::size_t end) {
    if (p.stopped()) return;
    for (std::size_t k = b; k < end; ++k) {
      const Vec3i c = chunks[k];
      const Box3i cb =
          Box3i{{c.x * e, c.y * e, c.z * e}, {c.x * e + e, c.y * e + e, c.z * e + e}}.intersect(
              p.box);
      const Box3i padded = cb.grown(1);
      World w(inner_edge, padded);
      std::vector<std::uint8_t> dense(static_cast<std::size_t>(padded.volume()));
      std::size_t i = 0;
      for (int z = padded.begin.z; z < padded.end.z; ++z)
        for (int y = padded.begin.y; y < padded.end.y; ++y)
          for (int x = padded.begin.x; x < padded.end.x; ++x, ++i) {
            const Vec3i q{x, y, z};
            // The padding counts as solid.
            dense[i] = !cb.contains(q) ||
                       p.site[p.index(x - p.box.begin.x, y - p.box.begin.y, z - p.box.begin.z)];
          }
      w.voxels.copy_from_dense(padded, dense.data());
      DistanceOptions o;
      o.metric = p.metric;
      o.spacing = p.spacing;
      o.nearest_sites = false;
      const DistanceField f = compute_distance_field(w, o);
      const Grid<float>& g = std::get<Grid<float>>(f.values);
      for (int z = cb.begin.z; z < cb.end.z; ++z)
        for (int y = cb.begin.y; y < cb.end.y; ++y)
          for (int x = cb.begin.x; x < cb.end.x; ++x) {
            out.d[p.index(x - p.box.begin.x, y - p.box.begin.y, z - p.box.begin.z)] =
                g.get({x, y, z});
          }
    }
  });
  // Sites are not tracked: many voxels are "nearest" to the padding, which is no real voxel.
  out.site.clear();
  stats.passes = static_cast<int>(chunks.size());
}

}  // namespace voxfield::detail
