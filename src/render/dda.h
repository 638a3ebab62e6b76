// voxfield renderer — Amanatides & Woo voxel traversal ("A Fast Voxel Traversal Algorithm for Ray
// Tracing", Eurographics 1987) with exact bulk skips.
//
// The traversal is a merge of three event sequences: crossing number j (j = 0, 1, ...) of the
// planes perpendicular to axis a happens at
//     t_a(j) = (boundary_a + j * step_a - origin_a) / direction_a,
// and the DDA processes events in increasing (t, axis) order — ties go to the lower axis. t_a(j) is
// always evaluated by that one formula, never accumulated, so it is monotone in j and every
// traversal of a ray (plain or skipping) agrees on the order of events to the last bit.
//
// Bulk skip ("leave"): given a box that contains the current voxel and extends caps[a] voxels
// ahead along each axis, the first event that leaves the box is the smallest (t_a(caps[a]), a).
// Every event before it is processed by the plain DDA too, and on each other axis b they are
// exactly the j with (t_b(j), b) < (t*, a*) — counted from an estimate that exact comparisons with
// the same formula settle. So a
// skip lands on precisely the voxel, face and t the plain DDA reaches when it first leaves the box.
// It is safe (cannot pass through geometry) whenever the box holds no solid voxel: the chunk
// table knows empty chunks, and a distance field bounds a box around every air voxel (why, per
// metric, at skip_caps() in traverse.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "voxfield/render.h"

namespace voxfield::render_detail {

struct Dda {
  Vec3i v{0, 0, 0};             // current voxel
  int step[3] = {0, 0, 0};      // -1, 0 or +1 per axis
  int boundary[3] = {0, 0, 0};  // the next plane crossed along each axis
  double origin[3] = {0, 0, 0};
  double inv[3] = {0, 0, 0};  // 1 / direction (unused where step is 0)
  double abs_dir[3] = {0, 0, 0};
  double t_next[3] = {0, 0, 0};  // t_a(0); +inf on axes the ray does not move along
  double t = 0;                  // where the ray entered v
  int face_axis = -1;            // axis crossed to enter v; -1 for the first voxel

  static constexpr double kInf = std::numeric_limits<double>::infinity();

  // Starts at voxel `start`, entered at parameter t0 through face `axis` (-1: none).
  void start(const Ray& ray, Vec3i start, double t0, int axis) {
    v = start;
    t = t0;
    face_axis = axis;
    for (int a = 0; a < 3; ++a) {
      const double d = ray.direction[a];
      origin[a] = ray.origin[a];
      step[a] = d > 0 ? 1 : d < 0 ? -1 : 0;
      inv[a] = step[a] != 0 ? 1.0 / d : 0.0;
      abs_dir[a] = std::abs(d);
      boundary[a] = start[a] + (step[a] > 0 ? 1 : 0);
      t_next[a] = step[a] != 0 ? t_at(a, 0) : kInf;
    }
  }

  double t_at(int a, int j) const {
    return (static_cast<double>(boundary[a] + j * step[a]) - origin[a]) * inv[a];
  }

  // The axis of the next event: the smallest t, ties to the lower axis.
  int next_axis() const {
    if (t_next[0] <= t_next[1] && t_next[0] <= t_next[2]) return 0;
    return t_next[1] <= t_next[2] ? 1 : 2;
  }

  void advance(int a, int n) {
    v[a] += n * step[a];
    boundary[a] += n * step[a];
    t_next[a] = t_at(a, 0);
  }

  // One plain DDA step.
  void step_once() {
    const int a = next_axis();
    t = t_next[a];
    face_axis = a;
    advance(a, 1);
  }

  struct Exit {
    double t;
    int axis;
  };
  // The event that first leaves the box reaching caps[a] voxels ahead of v along each axis.
  Exit exit_of(const int caps[3]) const {
    Exit e{kInf, 3};
    for (int a = 0; a < 3; ++a) {
      if (step[a] == 0) continue;
      const double ta = t_at(a, caps[a]);
      if (ta < e.t || (ta == e.t && a < e.axis)) e = {ta, a};
    }
    return e;
  }

  // Moves to the voxel the plain DDA enters when it leaves that box (see the header comment).
  void leave(const int caps[3], Exit e) {
    for (int b = 0; b < 3; ++b) {
      if (step[b] == 0) continue;
      if (b == e.axis) {
        advance(b, caps[b] + 1);
        continue;
      }
      // The smallest j in [0, caps[b]] whose event comes at or after the exit event (the events
      // before it are a prefix: t_at is monotone in j; and j = caps[b] comes after, as the exit
      // is the box's first). Crossings are 1 / |direction_b| apart in t, which gives j up to
      // rounding; exact comparisons with t_at() then settle it (they decide, not the estimate,
      // so the result is exact). The last t_at() they evaluate is the axis' next event.
      const auto before = [&](double tb) { return tb < e.t || (tb == e.t && b < e.axis); };
      int j = static_cast<int>(
          std::clamp(std::ceil((e.t - t_next[b]) * abs_dir[b]), 0.0, static_cast<double>(caps[b])));
      double tj = t_at(b, j);
      if (before(tj)) {
        do {
          ++j;
          tj = t_at(b, j);
        } while (j < caps[b] && before(tj));
      } else {
        while (j > 0) {
          const double earlier = t_at(b, j - 1);
          if (before(earlier)) break;
          --j;
          tj = earlier;
        }
      }
      v[b] += j * step[b];
      boundary[b] += j * step[b];
      t_next[b] = tj;
    }
    t = e.t;
    face_axis = e.axis;
  }
};

}  // namespace voxfield::render_detail
