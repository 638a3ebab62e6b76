// voxfield renderer — walking a group of rays in turns, so that their voxel reads overlap.
//
// On a large scene a primary ray's voxel read misses every cache level: the 512³ terrain's skip
// arena is 256 MiB, and one thread spent half of its traversal time on that one load (`perf
// annotate` of traverse(), 640×360). A ray's steps depend on each other; different rays' do not.
// So up to kRayGroup rays take turns here: each walks on until it needs a voxel (crossing empty
// chunks needs none), prefetches that voxel and hands over, and reads it on its next turn, after
// the other rays' work has hidden the load. This is group prefetching (Chen, Ailamaki, Gibbons &
// Mowry, "Improving Hash Join Performance through Prefetching", ICDE 2004) applied to voxel
// traversal.
//
// Each ray's walk is traverse()'s, step for step: the same DDA events, the same hit and the same
// counters. Only the order in which different rays' steps run changes.
#pragma once

#include "traverse.h"

namespace voxfield::render_detail {

// Rays walked in turns: two groups to a row of a frame's default 16-pixel tile. Not tuned
// beyond one quick sitting (4 was a little slower than 8, 16 no faster).
inline constexpr int kRayGroup = 8;

// Traces rays[0..n), n <= kRayGroup, through `box`: hits[i] is what traverse(s, box, rays[i],
// mode, skip, c, <no air callback>) returns, and `c` counts what those calls count.
inline void traverse_group(const RenderScene::Impl& s, const Box3i& box, const Ray* rays, int n,
                           SkipMode mode, const SkipSource& skip, TraversalCounters& c,
                           RayHit* hits) {
  struct Walk {
    Dda dda;
    SkipWeights sw;
    std::size_t chunk = 0;
    const std::uint16_t* cell = nullptr;  // the voxel to read next (prefetched)
  };
  const auto no_air = [](const Dda&, std::size_t) {};
  if (mode != SkipMode::kDistance) {
    // Without distance skips a ray reads many voxels (15 on the 512³ terrain skipping empty
    // chunks only, 107 with none), mostly neighbours in one brick: the turns cost more than they
    // hide (the plain DDA ran 1.1-1.3x slower in turns: docs/rendering.md).
    for (int i = 0; i < n; ++i) hits[i] = traverse(s, box, rays[i], mode, skip, c, no_air);
    return;
  }
  Walk walks[kRayGroup];  // walks[i] walks rays[i]
  // Walks w on to the next voxel it must read and prefetches that voxel; false when the ray left
  // the box (a miss).
  const auto to_next_read = [&](Walk& w) {
    for (;;) {
      if (!box.contains(w.dda.v)) return false;
      w.chunk = s.table.chunk_index(w.dda.v);
      if (!s.empty_chunk[w.chunk]) break;
      leave_empty_chunk(s, mode, skip, w.sw, w.dda, w.chunk, c, no_air);
    }
    w.cell = skip.address(w.chunk, s.table.brick_index(w.dda.v));
    __builtin_prefetch(w.cell);
    return true;
  };

  int live[kRayGroup];  // indices into walks of the rays still walking
  int live_count = 0;
  for (int i = 0; i < n; ++i) {
    ++c.rays;
    hits[i] = {};
    Walk& w = walks[i];
    if (!start_in_box(box, rays[i], w.dda)) continue;
    w.sw = SkipWeights(skip.metric, rays[i]);
    if (to_next_read(w)) live[live_count++] = i;
  }
  while (live_count > 0) {
    for (int k = 0; k < live_count;) {
      const int i = live[k];
      Walk& w = walks[i];
      ++c.voxel_reads;
      const Step step = after_read(mode, skip, w.sw, w.dda, w.chunk, *w.cell, c, no_air, hits[i]);
      if (step == Step::kContinue && to_next_read(w)) {
        ++k;
        continue;
      }
      // A hit (hits[i] is set) or a miss (it stays empty): this ray is done.
      live[k] = live[--live_count];
    }
  }
}

}  // namespace voxfield::render_detail
