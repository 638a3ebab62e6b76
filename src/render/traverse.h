// voxfield renderer — walking one ray through the scene: clip to the box, then DDA with empty-chunk
// and distance-field skips (dda.h), stopping at the first solid voxel.
#pragma once

#include <algorithm>
#include <cmath>

#include "dda.h"
#include "scene_impl.h"

namespace voxfield::render_detail {

// Per-ray constants turning a stored skip distance into the caps of a box free of solid voxels.
struct SkipWeights {
  double w[3] = {0, 0, 0};
  // Whether an empty chunk is left through the box extended beyond it (leave_empty_chunk).
  // Walks that sample the air where they stop (soft shadows' penumbra) keep the shorter skips:
  // fewer stops would sample less of the air and lighten the penumbra.
  bool beyond_empty_chunks = true;
  SkipWeights() = default;
  SkipWeights(Metric metric, const Ray& ray, bool samples_air = false)
      : beyond_empty_chunks(!samples_air) {
    const double ax = std::abs(ray.direction.x), ay = std::abs(ray.direction.y),
                 az = std::abs(ray.direction.z);
    double norm = 1;
    switch (metric) {
      case Metric::kManhattan:
        norm = ax + ay + az;
        break;
      case Metric::kChebyshev:
        norm = 0;
        break;
      case Metric::kEuclidean:
        norm = std::sqrt(ax * ax + ay * ay + az * az);
        break;
    }
    if (norm == 0) {
      w[0] = w[1] = w[2] = 1;
    } else {
      w[0] = ax / norm;
      w[1] = ay / norm;
      w[2] = az / norm;
    }
  }
};

// Caps of a box ahead of an air voxel v whose stored skip value is `stored` (see dda.h for how a
// box is left). Why each box holds no solid voxel:
//  * Manhattan: stored = d, the exact L1 distance from v to the nearest solid voxel (or the clamp,
//    a lower bound), so every voxel u with |u - v|_1 <= d - 1 is air. Caps with sum c_a = d - 1
//    reach no farther than that from v: the box lies inside the ball. This is the dissertation's
//    argument — k DDA steps stay within L1 distance k — applied to a whole box.
//  * Chebyshev: every u with |u - v|_inf <= d - 1 is air: the cube of caps d - 1 on every axis.
//  * Euclidean: stored = floor(4 d) so r = stored / 4 <= d; the box's farthest voxel lies at
//    sqrt(sum c_a^2) <= r' |w| < d with c_a = floor(r' w_a), |w| = 1, r' just below r.
// The caps follow the ray's direction so that it leaves the box through its far side.
inline void skip_caps(const SkipSource& skip, const SkipWeights& sw, std::uint8_t stored,
                      int caps[3]) {
  if (skip.metric == Metric::kEuclidean) {
    const double r = static_cast<double>(stored) * skip.inv_scale * (1 - 1e-9);
    for (int a = 0; a < 3; ++a) caps[a] = static_cast<int>(r * sw.w[a]);
    return;
  }
  const int r = stored > 0 ? stored - 1 : 0;
  if (skip.metric == Metric::kChebyshev) {
    caps[0] = caps[1] = caps[2] = r;
    return;
  }
  // Manhattan: split r over the axes in proportion to the direction, rounding by largest
  // remainders so that the caps use all of r (sum c_a = r exactly): near surfaces, where r is a few
  // voxels, plain rounding down would often leave nothing to skip.
  double rest[3];
  int used = 0;
  for (int a = 0; a < 3; ++a) {
    const double share = r * sw.w[a];
    caps[a] = static_cast<int>(share);
    rest[a] = sw.w[a] > 0 ? share - caps[a] : -1;
    used += caps[a];
  }
  // The `left` (0, 1 or 2: the remainders sum to less than 3, save rounding) axes of largest
  // remainder get one
  // more voxel each, ties to the lower axis. Ranked without branches: which axes win is different
  // at nearly every skip, and a loop picking them mispredicted most of its turns.
  const int left = r - used;
  const int rank0 = (rest[1] > rest[0]) + (rest[2] > rest[0]);
  const int rank1 = (rest[0] >= rest[1]) + (rest[2] > rest[1]);
  const int rank2 = (rest[0] >= rest[2]) + (rest[1] >= rest[2]);
  caps[0] += rank0 < left;
  caps[1] += rank1 < left;
  caps[2] += rank2 < left;
}

// Clips the ray to `box` and starts the DDA at its first voxel. False when the ray misses.
inline bool start_in_box(const Box3i& box, const Ray& ray, Dda& dda) {
  double t0 = -Dda::kInf, t1 = Dda::kInf;
  int axis0 = -1;
  for (int a = 0; a < 3; ++a) {
    const double o = ray.origin[a], d = ray.direction[a];
    if (d == 0) {
      if (o < box.begin[a] || o >= box.end[a]) return false;
      continue;
    }
    double ta = (box.begin[a] - o) / d, tb = (box.end[a] - o) / d;
    if (ta > tb) std::swap(ta, tb);
    if (ta > t0) {
      t0 = ta;
      axis0 = a;
    }
    t1 = std::min(t1, tb);
  }
  const double ts = std::max(t0, 0.0);
  if (!(t1 > ts)) return false;
  Vec3i v;
  for (int a = 0; a < 3; ++a) {
    const double p = ray.origin[a] + ray.direction[a] * ts;
    v[a] = std::clamp(static_cast<int>(std::floor(p)), box.begin[a], box.end[a] - 1);
  }
  const int face = t0 > 0 ? axis0 : -1;
  if (face >= 0) v[face] = ray.direction[face] > 0 ? box.begin[face] : box.end[face] - 1;
  dda.start(ray, v, ts, face);
  return true;
}

inline RayHit make_hit(const Dda& dda, std::uint8_t material) {
  RayHit h;
  h.hit = true;
  h.voxel = dda.v;
  h.face_axis = dda.face_axis;
  h.face_sign = dda.face_axis >= 0 ? -dda.step[dda.face_axis] : 0;
  h.t = dda.t;
  h.material = material;
  return h;
}

enum class Step { kContinue, kHit, kMiss };

// A traversal step at voxel dda.v of chunk `chunk` when the chunk holds no solid voxel (no voxel
// is read): leave the chunk in one step, or farther when the field allows it.
// Every voxel of the chunk is at least the chunk's smallest value away from geometry, so the box
// reaching from v to the chunk's far faces, extended beyond them by the caps that value gives
// (skip_caps), holds no solid voxel either: a voxel u of it lies within sum c_a (Manhattan),
// max c_a (Chebyshev) or sqrt(sum c_a^2) (Euclidean) of the chunk's nearest voxel — inside that
// voxel's air ball, by the same argument as at skip_caps. That box contains the chunk and the box
// the value gives around v, so it is left no earlier than either. A walk that samples the air
// (sw.beyond_empty_chunks false) leaves by the farther of those two instead.
template <class OnAir>
inline void leave_empty_chunk(const RenderScene::Impl& s, SkipMode mode, const SkipSource& skip,
                              const SkipWeights& sw, Dda& dda, std::size_t chunk,
                              TraversalCounters& c, OnAir& on_air) {
  const Box3i cb = s.table.chunk_box_of(dda.v);
  int caps[3];
  for (int a = 0; a < 3; ++a)
    caps[a] = dda.step[a] > 0 ? cb.end[a] - 1 - dda.v[a] : dda.v[a] - cb.begin[a];
  on_air(dda, chunk);
  ++c.steps;
  if (mode == SkipMode::kDistance) {
    int dcaps[3];
    skip_caps(skip, sw, skip.chunk_min[chunk], dcaps);
    if (!sw.beyond_empty_chunks) {
      const Dda::Exit exit = dda.exit_of(caps), dexit = dda.exit_of(dcaps);
      if (dexit.t > exit.t || (dexit.t == exit.t && dexit.axis > exit.axis)) {
        dda.leave(dcaps, dexit);
        ++c.distance_skips;
      } else {
        dda.leave(caps, exit);
        ++c.chunk_skips;
      }
      return;
    }
    for (int a = 0; a < 3; ++a) caps[a] += dcaps[a];
  }
  dda.leave(caps, dda.exit_of(caps));
  ++c.chunk_skips;
}

// A traversal step at voxel dda.v of chunk `chunk` in any other chunk, once the voxel has been read
// (`cell`, material in the high byte): a hit, or the DDA moves on by one step or a skip the
// distance field clears.
template <class OnAir>
inline Step after_read(SkipMode mode, const SkipSource& skip, const SkipWeights& sw, Dda& dda,
                       std::size_t chunk, std::uint16_t cell, TraversalCounters& c, OnAir& on_air,
                       RayHit& hit) {
  const auto material = static_cast<std::uint8_t>(cell >> 8);
  if (material != 0) {
    hit = make_hit(dda, material);
    return Step::kHit;
  }
  on_air(dda, chunk);
  ++c.steps;
  if (mode == SkipMode::kDistance) {
    int caps[3];
    skip_caps(skip, sw, static_cast<std::uint8_t>(cell & 0xFF), caps);
    if (caps[0] + caps[1] + caps[2] > 0) {
      dda.leave(caps, dda.exit_of(caps));
      ++c.distance_skips;
      return Step::kContinue;
    }
  }
  dda.step_once();
  return Step::kContinue;
}

// One iteration of the traversal at dda.v: a hit, a miss (the ray left `box`), or the DDA moved on
// (one step, or a skip out of an empty chunk or a box the distance field clears). on_air(dda,
// chunk) is called at every air voxel the traversal stops at (with kNone: every air voxel on the
// ray).
template <class OnAir>
inline Step visit(const RenderScene::Impl& s, const Box3i& box, SkipMode mode,
                  const SkipSource& skip, const SkipWeights& sw, Dda& dda, TraversalCounters& c,
                  OnAir& on_air, RayHit& hit) {
  if (!box.contains(dda.v)) return Step::kMiss;
  const std::size_t chunk = s.table.chunk_index(dda.v);
  if (mode != SkipMode::kNone && s.empty_chunk[chunk]) {
    leave_empty_chunk(s, mode, skip, sw, dda, chunk, c, on_air);
    return Step::kContinue;
  }
  ++c.voxel_reads;
  return after_read(mode, skip, sw, dda, chunk, skip.read(chunk, s.table.brick_index(dda.v)), c,
                    on_air, hit);
}

// The first solid voxel along the ray inside `box` (a sub-box of the scene's). samples_air: on_air
// samples the air where the walk stops (SkipWeights::beyond_empty_chunks).
template <class OnAir>
RayHit traverse(const RenderScene::Impl& s, const Box3i& box, const Ray& ray, SkipMode mode,
                const SkipSource& skip, TraversalCounters& c, OnAir&& on_air,
                bool samples_air = false) {
  ++c.rays;
  Dda dda;
  if (!start_in_box(box, ray, dda)) return {};
  const SkipWeights sw(skip.metric, ray, samples_air);
  RayHit hit;
  for (;;) {
    switch (visit(s, box, mode, skip, sw, dda, c, on_air, hit)) {
      case Step::kContinue:
        break;
      case Step::kHit:
        return hit;
      case Step::kMiss:
        return {};
    }
  }
}

}  // namespace voxfield::render_detail
