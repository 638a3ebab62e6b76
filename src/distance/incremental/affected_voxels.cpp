// voxfield — which voxels of an update region an edit can move, and which sites their new values
// can reach (internal; update_regions.h): the searches that let DynamicDistanceField::update
// recompute in proportion to the edit rather than to the clamp's reach box.
//
// Distances are 1-Lipschitz: a voxel whose old distance does not reach a changed voxel keeps its
// value bit for bit, and new values are bounded by the unchanged values around them. The
// searches compare distances as costs (squared for Euclidean, so no square root per voxel) in
// floats with bounds rounded up, so a voxel is let through whenever in doubt; the exact kernel
// (exact/local_region.cpp) then recomputes what they let through. docs/distance.md,
// "Incremental updates", explains the bounds.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

#include "update_regions.h"

namespace voxfield::detail {
namespace {

// An upper bound of the distance an unsigned stored value stands for: integer storage rounds
// down (d < (stored + 1) / scale) and the clamp value stands for "at least the clamp" (+inf);
// f32 is exact up to its rounding.
template <class T>
double upper_distance(const FieldPlan& plan, T stored, T clamp_stored) {
  if (stored == clamp_stored) return std::numeric_limits<double>::infinity();
  if constexpr (std::is_same_v<T, float>) {
    return static_cast<double>(stored) * (1 + 1e-6) + 1e-6;
  } else {
    return (static_cast<double>(stored) + 1) / plan.encoding.scale;
  }
}

// Cost-space helpers shared by the searches below: distances are compared as costs (squared for
// Euclidean, so no square root per voxel), per-axis gaps to the changed box combined per metric.
struct GapCost {
  Metric metric;
  Box3i changed;
  std::array<double, 3> spacing;
  float axis(int k, int v) const {  // the gap along axis k, as a cost term
    const float g = static_cast<float>(
        std::max({0, changed.begin[k] - v, v - (changed.end[k] - 1)}) * spacing[k]);
    return metric == Metric::kEuclidean ? g * g : g;
  }
  float combine(float a, float b) const {
    return metric == Metric::kChebyshev ? std::max(a, b) : a + b;
  }
};

// The largest gap cost (GapCost's units) from a change at which a voxel holding `stored` can still
// be moved by it: its distance bound upper_distance() plus `extra`, as (stored + off) * mul +
// extra, then squared for Euclidean. A few float operations per voxel that vectorise, with margins
// wider than upper_distance()'s and far wider than float rounding, so the bound is never below the
// exact one (a voxel is let through whenever in doubt). Values that cannot change get kNever.
template <class T>
struct StoredBound {
  static constexpr float kNever = -1.0f;  // below every cost
  float off, mul, extra;
  T clamp_stored;
  float at_clamp;    // +inf (the clamp value stands for "at least the clamp"), or kNever
  bool zero_frozen;  // a voxel at 0 keeps its value (the changes only added sites)
  bool squared;      // Euclidean costs are squared distances

  // `extra`: a distance added to every bound. `clamp_frozen`: values at the clamp cannot change
  // (the changes only removed sites, so values can only rise).
  StoredBound(const FieldPlan& plan, double extra_distance, bool clamp_frozen,
              bool zero_frozen_value)
      : off(std::is_same_v<T, float> ? 1e-5f : 1.0f),
        mul(static_cast<float>((std::is_same_v<T, float> ? 1.0 : 1.0 / plan.encoding.scale) *
                               (1 + 1e-5))),
        extra(static_cast<float>(extra_distance * (1 + 1e-5))),
        clamp_stored(encode_distance<T>(plan.clamp, plan)),
        at_clamp(clamp_frozen ? kNever : std::numeric_limits<float>::infinity()),
        zero_frozen(zero_frozen_value),
        squared(plan.metric == Metric::kEuclidean) {}

  template <bool kSquared>
  float at(T s) const {
    const float d = (static_cast<float>(s) + off) * mul + extra;
    float b = (kSquared ? d * d : d) * 1.0001f + 1e-4f;
    b = s == clamp_stored ? at_clamp : b;
    return (zero_frozen & (s == T{0})) ? kNever : b;
  }
  float operator()(T s) const { return squared ? at<true>(s) : at<false>(s); }
};

// flags[i] = 1 when voxel i of a row segment passes: the combination of its gap cost along x
// (gx[i]) with the rest of its gap (`rest`) is within the bound of its stored value v[i]. One
// branch-free loop per metric. (Arguments by value and __restrict pointers: nothing the loop reads
// may be thought to alias its stores, or it stays scalar.)
template <bool kSquared, bool kChebyshev, class T>
void test_loop(const StoredBound<T> sb, const T* __restrict v, const float* __restrict gx,
               int count, float rest, std::uint32_t* __restrict flags) {
  for (int i = 0; i < count; ++i) {
    const float cost = kChebyshev ? std::max(gx[i], rest) : gx[i] + rest;
    flags[i] = cost <= sb.template at<kSquared>(v[i]) ? 1u : 0u;
  }
}

template <class T>
void test_segment(Metric metric, const StoredBound<T>& sb, const T* v, const float* gx, int count,
                  float rest, std::uint32_t* flags) {
  switch (metric) {
    case Metric::kEuclidean:
      test_loop<true, false>(sb, v, gx, count, rest, flags);
      break;
    case Metric::kManhattan:
      test_loop<false, false>(sb, v, gx, count, rest, flags);
      break;
    case Metric::kChebyshev:
      test_loop<false, true>(sb, v, gx, count, rest, flags);
      break;
  }
}

// The first and last set flags of flags[0..count); false when none is set.
inline bool flagged_span(const std::uint32_t* flags, int count, int& first, int& last) {
  first = 0;
  while (first < count && !flags[first]) ++first;
  if (first == count) return false;
  last = count - 1;
  while (!flags[last]) --last;
  return true;
}

}  // namespace

template <class T>
Box3i affected_box(const FieldPlan& plan, const Box3i& r, const std::vector<T>& old,
                   const Box3i& changed, Changes kind) {
  // Only a voxel whose old distance reaches the changed voxels can change: a removed site that
  // was its nearest lies at least that far away, and a new site nearer than its old distance lies
  // at least that far away too. Everything else keeps its value — bit for bit — so the
  // recomputation shrinks to the bounding box of the voxels that pass this test.
  //
  // Distances are compared as "costs" (squared for Euclidean, so no square root per voxel) in
  // floats, with the bound rounded up a little: a voxel is let through whenever in doubt.
  const GapCost gap{plan.metric, changed, plan.spacing};
  // Values can only rise after removals (one at the clamp stays there) and only fall after
  // additions (one at 0 stays there).
  const StoredBound<T> bound(plan, 0.0, kind == Changes::kRemovals, kind == Changes::kAdditions);
  const int nx = r.size().x;
  std::vector<float> gx(static_cast<std::size_t>(nx));
  std::vector<std::uint32_t> pass(static_cast<std::size_t>(nx));
  for (int x = 0; x < nx; ++x) gx[static_cast<std::size_t>(x)] = gap.axis(0, r.begin.x + x);
  Box3i box{r.end, r.begin};  // empty
  std::size_t i = 0;
  for (int z = r.begin.z; z < r.end.z; ++z) {
    const float gz = gap.axis(2, z);
    for (int y = r.begin.y; y < r.end.y; ++y, i += static_cast<std::size_t>(nx)) {
      test_segment(plan.metric, bound, old.data() + i, gx.data(), nx,
                   gap.combine(gap.axis(1, y), gz), pass.data());
      int first, last;
      if (!flagged_span(pass.data(), nx, first, last)) continue;
      box = {{std::min(box.begin.x, r.begin.x + first), std::min(box.begin.y, y),
              std::min(box.begin.z, z)},
             {std::max(box.end.x, r.begin.x + last + 1), std::max(box.end.y, y + 1),
              std::max(box.end.z, z + 1)}};
    }
  }
  return box;
}

namespace {

// Reads rows of a field grid inside a box, chunk by chunk, with the box's chunks looked up once.
template <class T>
class RowReader {
 public:
  RowReader(const Grid<T>& grid, const Box3i& box)
      : shift_(grid.chunk_shift()), edge_(grid.chunk_edge()) {
    lo_ = grid.chunk_of(box.begin);
    const Vec3i hi = grid.chunk_of(box.end - Vec3i::splat(1));
    n_ = hi - lo_ + Vec3i::splat(1);
    views_.reserve(static_cast<std::size_t>(n_.x) * n_.y * n_.z);
    for (int z = lo_.z; z <= hi.z; ++z)
      for (int y = lo_.y; y <= hi.y; ++y)
        for (int x = lo_.x; x <= hi.x; ++x) views_.push_back(grid.chunk_view({x, y, z}));
  }
  // Calls run(x_begin, x_end, value) for runs of one value (a uniform chunk's part of the row) and
  // segment(x_begin, x_end, values) for the parts in dense chunks (values[0] at x_begin), over x in
  // [x0, x1) of the row (y, z).
  template <class Run, class Segment>
  void row(int x0, int x1, int y, int z, Run&& run, Segment&& segment) const {
    const std::size_t base = (static_cast<std::size_t>((z >> shift_) - lo_.z) * n_.y +
                              static_cast<std::size_t>((y >> shift_) - lo_.y)) *
                             n_.x;
    for (int x = x0; x < x1;) {
      const ChunkView<T>& v = views_[base + static_cast<std::size_t>((x >> shift_) - lo_.x)];
      const int end = std::min(x1, v.box.end.x);
      if (v.uniform()) {
        run(x, end, v.uniform_value);
      } else {
        const T* row = v.voxels + (static_cast<std::size_t>(z - v.box.begin.z) * edge_ +
                                   static_cast<std::size_t>(y - v.box.begin.y)) *
                                      edge_;
        segment(x, end, row + (x - v.box.begin.x));
      }
      x = end;
    }
  }

 private:
  int shift_, edge_;
  Vec3i lo_, n_;
  std::vector<ChunkView<T>> views_;
};

// The distance a rounding of a point to its nearest voxel can add, twice (see grow_affected).
double rounding_slack(const FieldPlan& plan) {
  const double hx = plan.spacing[0] / 2, hy = plan.spacing[1] / 2, hz = plan.spacing[2] / 2;
  switch (plan.metric) {
    case Metric::kManhattan:
      return 2 * (hx + hy + hz);
    case Metric::kChebyshev:
      return 2 * std::max({hx, hy, hz});
    case Metric::kEuclidean:
      break;
  }
  return 2 * std::sqrt(hx * hx + hy * hy + hz * hz);
}

}  // namespace

template <class T>
Box3i grow_affected(const FieldPlan& plan, const Grid<T>& field, const Box3i& r,
                    const Box3i& changed, std::int64_t max_volume) {
  // Every voxel p that an edit can change has g(p) <= old(p), g being its distance to the changed
  // box C (see affected_box). Walk from p straight to its nearest point c of C, rounding each point
  // of the segment to its nearest voxel q: g falls exactly as fast as the walk advances, the old
  // field (a distance, clamped or not) falls at most that fast, and the rounding moves each by at
  // most half a voxel diagonal. So every q on the walk has g(q) <= old(q) + s, s = twice that
  // half-diagonal in the field's metric, and consecutive q are 26-neighbours: p is joined to C by
  // voxels passing the relaxed test. A box that no passing voxel just outside it extends therefore
  // holds every voxel the edit can change. It is found by growing C one shell at a time, reading
  // each voxel at most once: work in proportion to the affected voxels, not to the reach box.
  const GapCost gap{plan.metric, changed, plan.spacing};
  // Every value relaxed by the rounding slack; nothing is frozen (a search must pass through).
  const StoredBound<T> bound_of(plan, rounding_slack(plan), false, false);
  const float inf = std::numeric_limits<float>::infinity();
  const int nx = r.size().x;
  std::vector<float> gx(static_cast<std::size_t>(nx));  // gap costs along x, index x - r.begin.x
  for (int x = 0; x < nx; ++x) gx[static_cast<std::size_t>(x)] = gap.axis(0, r.begin.x + x);
  const RowReader<T> reader(field, r);
  Box3i box = changed.intersect(r), scanned = box;
  while (box != r) {
    if (box.volume() > max_volume) return r;
    const Box3i outer = Box3i{box.begin - Vec3i::splat(1), box.end + Vec3i::splat(1)}.intersect(r);
    Box3i grown = box;
    for (int z = outer.begin.z; z < outer.end.z; ++z) {
      const float gz = gap.axis(2, z);
      for (int y = outer.begin.y; y < outer.end.y; ++y) {
        const float rest = gap.combine(gap.axis(1, y), gz);
        int lo = INT32_MAX, hi = INT32_MIN;
        auto segment = [&](int x0, int x1, const T* values) {
          // Mostly a voxel or two at the ends of rows already scanned: tested one by one.
          for (int x = x0; x < x1; ++x) {
            if (gap.combine(gx[static_cast<std::size_t>(x - r.begin.x)], rest) >
                bound_of(values[x - x0]))
              continue;
            lo = std::min(lo, x);
            hi = std::max(hi, x);
          }
        };
        auto run = [&](int x0, int x1, T stored) {
          // A run at the clamp passes whole (open space); otherwise the passing voxels of a run of
          // one bound form an interval around the changed box's x range, so its ends are found by
          // walking in from the run's ends.
          const float bound = bound_of(stored);
          if (bound == inf) {
            lo = std::min(lo, x0);
            hi = std::max(hi, x1 - 1);
            return;
          }
          const float* g = gx.data() - r.begin.x;  // g[x]: x's gap cost along x
          const int nearest = std::clamp(changed.begin.x, x0, x1 - 1);  // the run's voxel nearest C
          const int nearest2 = std::clamp(changed.end.x - 1, x0, x1 - 1);
          if (gap.combine(std::min(g[nearest], g[nearest2]), rest) > bound) return;
          int a = x0, b = x1 - 1;
          while (a <= b && gap.combine(g[a], rest) > bound) ++a;
          while (b >= a && gap.combine(g[b], rest) > bound) --b;
          if (a <= b) {
            lo = std::min(lo, a);
            hi = std::max(hi, b);
          }
        };
        const bool inner_row =
            y >= scanned.begin.y && y < scanned.end.y && z >= scanned.begin.z && z < scanned.end.z;
        if (inner_row) {  // only the ends of this row are new
          reader.row(outer.begin.x, scanned.begin.x, y, z, run, segment);
          reader.row(scanned.end.x, outer.end.x, y, z, run, segment);
        } else {
          reader.row(outer.begin.x, outer.end.x, y, z, run, segment);
        }
        if (lo <= hi) grown = grown.unite(Box3i{{lo, y, z}, {hi + 1, y + 1, z + 1}});
      }
    }
    scanned = outer;
    if (grown == box) break;
    box = grown;
  }
  return box;
}

template Box3i grow_affected<std::uint8_t>(const FieldPlan&, const Grid<std::uint8_t>&,
                                           const Box3i&, const Box3i&, std::int64_t);
template Box3i grow_affected<std::uint16_t>(const FieldPlan&, const Grid<std::uint16_t>&,
                                            const Box3i&, const Box3i&, std::int64_t);
template Box3i grow_affected<float>(const FieldPlan&, const Grid<float>&, const Box3i&,
                                    const Box3i&, std::int64_t);

template <class T>
NewValueBounds new_value_bound(const FieldPlan& plan, const Grid<T>& field, const Box3i& r,
                               const Box3i& a) {
  const T clamp_stored = encode_distance<T>(plan.clamp, plan);
  const double inf = std::numeric_limits<double>::infinity();
  const RowReader<T> reader(field, r);
  // The largest upper bound of the old values on the face slab `f` (inf if any is at the clamp).
  auto face_max = [&](const Box3i& f) {
    double m = 0;
    for (int z = f.begin.z; z < f.end.z && m < inf; ++z)
      for (int y = f.begin.y; y < f.end.y && m < inf; ++y)
        reader.row(
            f.begin.x, f.end.x, y, z,
            [&](int, int, T stored) {
              m = std::max(m, upper_distance<T>(plan, stored, clamp_stored));
            },
            [&](int x0, int x1, const T* values) {
              for (int i = 0; i < x1 - x0; ++i)
                m = std::max(m, upper_distance<T>(plan, values[i], clamp_stored));
            });
    return m;
  };
  NewValueBounds bounds;
  for (int k = 0; k < 3; ++k) {
    double& lo_face = bounds.lo_face[static_cast<std::size_t>(k)];
    double& hi_face = bounds.hi_face[static_cast<std::size_t>(k)];
    if (a.begin[k] > r.begin[k]) {
      Box3i f = a;
      f.begin[k] = a.begin[k] - 1;
      f.end[k] = a.begin[k];
      lo_face = face_max(f);
    }
    if (a.end[k] < r.end[k]) {
      Box3i f = a;
      f.begin[k] = a.end[k];
      f.end[k] = a.end[k] + 1;
      hi_face = face_max(f);
    }
    if (lo_face == inf && hi_face == inf) continue;
    // The worst voxel along axis k, each bounded through the nearer-valued face.
    double worst = 0;
    for (int v = a.begin[k]; v < a.end[k]; ++v)
      worst = std::max(worst, std::min(lo_face + (v - a.begin[k] + 1) * plan.spacing[k],
                                       hi_face + (a.end[k] - v) * plan.spacing[k]));
    // max over p of min over axes = min over axes of each axis's max (the axes vary independently).
    bounds.all = std::min(bounds.all, worst);
  }
  return bounds;
}

// A box holding every solid voxel of `box` (empty if it holds none), from the chunks alone: a
// chunk of air is skipped, any other adds its part of `box` — no voxel is read.
Box3i solid_bounds(const Grid<std::uint8_t>& occupancy, const Box3i& box) {
  Box3i bounds;
  if (box.empty()) return bounds;
  const Vec3i lo = occupancy.chunk_of(box.begin),
              hi = occupancy.chunk_of(box.end - Vec3i::splat(1));
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) {
        const ChunkView<std::uint8_t> view = occupancy.chunk_view({x, y, z});
        if (view.uniform() && view.uniform_value == 0) continue;
        bounds = bounds.unite(view.box.intersect(box));
      }
  return bounds;
}

template Box3i affected_box<std::uint8_t>(const FieldPlan&, const Box3i&,
                                          const std::vector<std::uint8_t>&, const Box3i&, Changes);
template Box3i affected_box<std::uint16_t>(const FieldPlan&, const Box3i&,
                                           const std::vector<std::uint16_t>&, const Box3i&,
                                           Changes);
template Box3i affected_box<float>(const FieldPlan&, const Box3i&, const std::vector<float>&,
                                   const Box3i&, Changes);
template NewValueBounds new_value_bound<std::uint8_t>(const FieldPlan&, const Grid<std::uint8_t>&,
                                                      const Box3i&, const Box3i&);
template NewValueBounds new_value_bound<std::uint16_t>(const FieldPlan&, const Grid<std::uint16_t>&,
                                                       const Box3i&, const Box3i&);
template NewValueBounds new_value_bound<float>(const FieldPlan&, const Grid<float>&, const Box3i&,
                                               const Box3i&);

}  // namespace voxfield::detail
