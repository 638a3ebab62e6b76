// What the vector-field passes share: sources as segments, the distance and score at a voxel
// centre, and the voxel centres themselves — computed the same way, in the same order, by every
// algorithm and by the oracle, so that equal winners are bit-for-bit equal values.
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <span>
#include <string_view>
#include <vector>

#include "voxfield/vectors.h"

namespace voxfield::detail::vectors {

// A source's segment a + t (b - a), t in [0, 1], and radius.
struct Segment {
  Vec3d a, ab;
  double ab2 = 0;  // |b - a|^2; 0 for a stationary source (its distance is |p - a|: no 0 / 0)
  double radius = 1;
};

inline Segment segment_of(const VectorSource& s) {
  const Vec3d ab = s.position - s.previous;
  return {s.previous, ab, dot(ab, ab), s.radius};
}

// The parameter of the point of the segment nearest p: clamp(dot(p - a, ab) / ab2, 0, 1), 0 for a
// stationary source. The division is done only where the clamp may not decide: a correctly
// rounded quotient is monotone, so below -ab2 it is at most -1 (clamped to +0, never -0) and at
// or above a finite ab2 at least 1 (clamped to 1) — the same doubles as dividing every time, at
// a tenth of the divisions for the paper's sources (segments a tenth of their radius long).
inline double segment_t(const Segment& s, Vec3d p) {
  if (!(s.ab2 > 0)) return 0;
  const double along = dot(p - s.a, s.ab);
  if (along < -s.ab2) return 0;
  if (along >= s.ab2 && s.ab2 < std::numeric_limits<double>::infinity()) return 1;
  return std::clamp(along / s.ab2, 0.0, 1.0);
}

// Distance from p to the segment; q receives the nearest point.
inline double distance_to(const Segment& s, Vec3d p, Vec3d& q) {
  const double t = segment_t(s, p);
  q = s.a + s.ab * t;
  return (p - q).length();
}

// Direction and strength at p for a source (zero, source -1, when it does not cover p).
inline VectorValue value_of(const Segment& s, Vec3d p, int index) {
  Vec3d q;
  const double d = distance_to(s, p, q);
  VectorValue v;
  if (!(d < s.radius)) return v;
  v.source = index;
  v.strength = 1.0 - d / s.radius;
  if (d > 0) v.direction = (p - q) * (1.0 / d);
  return v;
}

inline VectorTexel texel_of(const VectorValue& v) {
  return {static_cast<float>(v.direction.x), static_cast<float>(v.direction.y),
          static_cast<float>(v.direction.z), static_cast<float>(v.strength)};
}

std::vector<Segment> segments_of(std::span<const VectorSource> sources);

// Larger is better: the strength 1 - d / r for the paper's figure rule, -d for the nearest rule.
// Comparisons are strict, so of two equal scores the earlier (lower) index stays.
inline double score(VectorRule rule, double d, double radius) {
  return rule == VectorRule::kStrongest ? 1.0 - d / radius : -d;
}

// Voxel centres as ((centre + Z[k]) + Y[j]) + X[i] (in that order: a row's base is computed once
// and each voxel adds its X), each table the box axis times the voxel's local coordinate:
// VectorVolume::voxel_centre uses the same expression, so every pass sees the same doubles.
struct CentreTables {
  Vec3d centre;
  std::vector<Vec3d> x, y, z;
  explicit CentreTables(const VectorVolume& v);
  Vec3d row(int j, int k) const { return centre + z[k] + y[j]; }
  Vec3d at(int i, int j, int k) const { return row(j, k) + x[i]; }
};

// The axis offset of voxel n of `count` along an axis of length `size`, direction `column`.
inline Vec3d axis_offset(Vec3d column, double size, int n, int count) {
  const double local = ((n + 0.5) / count - 0.5) * size;
  return column * local;
}

// The voxels a source can cover: inclusive index ranges, empty when it misses the box.
struct IndexBox {
  int lo[3] = {0, 0, 0}, hi[3] = {-1, -1, -1};
  bool empty() const { return hi[0] < lo[0] || hi[1] < lo[1] || hi[2] < lo[2]; }
};
IndexBox index_box(const VectorVolume& v, const VectorSource& s);

// Runs body(k_begin, k_end) over z slabs of the volume in parallel, reporting each slab to the
// interrupter; throws Cancelled (naming `what`) when it says stop.
void for_each_slab(const VectorVolume& v, Interrupter* interrupter, std::string_view what,
                   const std::function<void(int k_begin, int k_end)>& body);

// Milliseconds since `start` (steady clock).
double ms_since(std::int64_t start_ns);
std::int64_t now_ns();

// The algorithms (one per file).
void brute_winners(const VectorVolume& v, std::span<const Segment> sources, VectorRule rule,
                   Interrupter* interrupter, std::span<std::int32_t> winners);
// The texels [lo, hi) of one row of a volume (rows are at most 4096 texels); empty when lo >= hi.
struct RowSpan {
  std::uint16_t lo = 0, hi = 0;
  bool empty() const { return lo >= hi; }
};

// One z slab's splat, layers [k0, k1), its arrays indexed from voxel (0, 0, k0): each voxel's
// winner (-1: none) and best score; for a step, also each winner's direction and strength
// (value_of's arithmetic on the distance the search computed anyway, valid where winners >= 0,
// so the sweep encodes them without computing the distance again; encoding here instead, once
// per improvement rather than once per texel, measured slower) and, per row j + ny (k - k0), the
// voxels [lo, hi) where some source won: what the sweep must convert.
struct SlabSplat {
  int k0 = 0, k1 = 0;
  std::int32_t* winners = nullptr;
  double* best = nullptr;
  VectorTexel* texels = nullptr;
  RowSpan* won = nullptr;
};

// Splatting into whole-volume arrays (generate_vectors): winners and best, -1 and -inf on entry.
void splat_winners(const VectorVolume& v, std::span<const VectorSource> sources,
                   std::span<const Segment> segments, VectorRule rule, Interrupter* interrupter,
                   std::span<std::int32_t> winners, std::span<double> best);

// A step's splatting: each z slab is splatted into a buffer of slab size (winners, scores,
// texels and row spans: about 1 MB at 128^2 x 2 layers, so it stays in the core's cache, where a
// volume-sized one went to memory on every write), then after_slab runs on it on the same thread
// — the step's sweep of those rows — and the buffer is cleared where it was written and reused
// by the next slab. The pool keeps one buffer per thread between steps.
class SlabPool {
 public:
  struct Buffer;
  SlabPool();
  ~SlabPool();
  std::unique_ptr<Buffer> acquire(const VectorVolume& v, int layers);
  void release(std::unique_ptr<Buffer> buffer);

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<Buffer>> free_;
};
void splat_slabs(const VectorVolume& v, std::span<const VectorSource> sources,
                 std::span<const Segment> segments, VectorRule rule, SlabPool& pool,
                 const std::function<void(const SlabSplat&)>& after_slab,
                 std::atomic<std::int64_t>* splat_ns);

// The visualiser's camera, shared by the CPU's render_vectors and the GPU's view pass: the view
// checked (InvalidArgument naming what is wrong), the eye and its basis, the march step and the
// density per world unit.
struct ViewCamera {
  Vec3d eye, forward, right, up;
  double tan_half = 0, aspect = 1, step = 0, density = 0;
};
ViewCamera view_camera(const VectorVolume& v, const VectorViewOptions& view);

// Jump flooding's seeding of one source: the part of its segment within its radius of the box,
// sampled at the samples + 1 points t0 + (t1 - t0) * (t / samples), t = 0..samples, each seeding
// the voxel it falls in (clamped to the volume). samples = -1: the source seeds nothing (it cannot
// reach a voxel centre). The GPU's seeding pass samples the same points.
struct SeedSpan {
  double t0 = 0, t1 = 0;
  int samples = -1;
};
SeedSpan seed_span(const VectorVolume& v, const VectorSource& source, const Segment& segment);
// The jumps of the flooding passes: N/2 ... 1 for the longest axis N, then 1 (JFA+1) or 2 and 1
// (JFA+2); none for a volume one voxel across.
std::vector<int> jfa_steps(const VectorVolume& v, int extra_passes);
void jfa_winners(const VectorVolume& v, std::span<const VectorSource> sources,
                 std::span<const Segment> segments, VectorRule rule, int extra_passes,
                 Interrupter* interrupter, std::span<std::int32_t> winners, VectorPassTimes* times);

}  // namespace voxfield::detail::vectors
