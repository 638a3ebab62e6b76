// voxfield — slice input and output of the exact transform's passes B and C (internal): a slice's
// g values (pass A's distances along z) into the costs a slice solver minimises, and its solved
// costs back into stored values and nearest-site offsets.
//
// One slice I/O for both drivers of Meijster, Roerdink & Hesselink's separable transform (2000):
// the whole-field pass reads and writes chunk rows piece by piece (whole_field.cpp), local
// recomputation reads dense rows of its input box and writes those of its output box
// (local_region.cpp), and both go through the row functions here, so that an incremental update
// stores exactly what a full computation stores. The truncated min-convolution path (Felzenszwalb
// & Huttenlocher 2012) has its own pair, its inputs and outputs being the solver's 16-bit rows.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../truncated_min_convolution.h"
#include "encoder.h"
#include "slice_solvers.h"
#include "voxfield/detail/vector_clones.h"

namespace voxfield::detail::exact {

// How g becomes a cost of the slice solvers (cost type V) and which costs still have a site
// within the clamp. Built once per transform from the plan.
template <class V>
struct SliceCosts {
  SliceCosts(const Plan& p, V inf_cost)
      : inf(inf_cost),
        clamp(clamp_cost(p) >= static_cast<double>(inf_cost) ? inf_cost
                                                             : static_cast<V>(clamp_cost(p))),
        euclid(p.metric == Metric::kEuclidean),
        unit_spacing(p.unit_spacing),
        spacing_z(p.spacing[2]),
        is_signed(p.is_signed) {}

  V inf;    // "no site"
  V clamp;  // the largest cost within the clamp
  bool euclid, unit_spacing;
  double spacing_z;  // distance units per voxel along z
  bool is_signed;
};

// One row of `count` voxels of a slice into a slice solver's inputs. g (in voxels along z;
// `cap_vox` or more for none) becomes its cost: Euclidean costs are squared distances, and those
// beyond the clamp are dropped as none already (the 2-D passes only add to them). Signed fields
// split the cost into the distance to solid (f0, for air voxels) and to air (f1, not null, for
// solid ones). `solid`, when not null, receives which voxels are solid: the write-back needs them
// for signed fields and nearest sites, and a caller that holds them already passes null.
// (gather_row and write_row twice: in AVX2 too, vector_clones.h — loops of conversions and
// selects over a row that vectorise.)
template <class V, class G>
VOXFIELD_AVX2_CLONE void gather_row(const SliceCosts<V>& costs, const G* g, G cap_vox,
                                    const std::uint8_t* world, int count, V* f0, V* f1,
                                    std::uint8_t* solid) {
  // Copied out: V pointers could otherwise alias these fields, and the loops would reload them.
  const V inf = costs.inf, clamp = costs.clamp;
  const bool euclid = costs.euclid, unit_spacing = costs.unit_spacing;
  const double sz = costs.spacing_z;
  for (int i = 0; i < count; ++i) {
    V c;
    if (euclid) {
      const double gz = unit_spacing ? static_cast<double>(g[i]) : sz * g[i];
      c = g[i] >= cap_vox ? inf : static_cast<V>(gz * gz);
      c = c > clamp ? inf : c;
    } else {
      c = g[i] >= cap_vox ? inf : static_cast<V>(g[i]);
    }
    f0[i] = c;
  }
  if (f1 && solid) {
    for (int i = 0; i < count; ++i) {
      const bool s = world[i] != 0;
      solid[i] = s;
      f1[i] = s ? f0[i] : V(0);  // distance to air
      f0[i] = s ? V(0) : f0[i];  // distance to solid
    }
  } else if (f1) {
    for (int i = 0; i < count; ++i) {
      const bool s = world[i] != 0;
      f1[i] = s ? f0[i] : V(0);
      f0[i] = s ? V(0) : f0[i];
    }
  } else if (solid) {
    for (int i = 0; i < count; ++i) solid[i] = world[i] != 0;
  }
}

// Stores `count` solved voxels of row y of a slice, from column x0, into `out`, and when `sites`
// is not null their nearest-site offsets into `sites`. The slice is row-major, `width` voxels a
// row: buf[0].h holds the solved costs (buf[1].h the distances to air of a signed field), `solid`
// which voxels are solid (for signed fields and sites) and `dz` pass A's z offsets (sites only).
template <class T, class V>
VOXFIELD_AVX2_CLONE void write_row(const Encoder<T>& encoder, const SliceCosts<V>& costs,
                                   const SliceBuffers<V>* buf, const std::uint8_t* solid,
                                   const std::int16_t* dz, int width, int y, int x0, int count,
                                   T* out, SiteOffset* sites) {
  const V inf = costs.inf, clamp = costs.clamp;
  const bool is_signed = costs.is_signed;
  const std::size_t o = static_cast<std::size_t>(y) * width + x0;
  if (encoder.row_path) {
    encoder.encode_row(buf[0].h.data() + o, out, count, inf, clamp);
  } else {
    for (int i = 0; i < count; ++i) {
      const bool inside = is_signed && solid[o + i];
      const V cost = buf[inside ? 1 : 0].h[o + i];
      const bool has_site = cost < inf && cost <= clamp;
      out[i] = encoder.encode(static_cast<double>(cost), has_site, inside);
    }
  }
  if (!sites) return;
  for (int i = 0; i < count; ++i) {
    const int x = x0 + i;
    const bool inside = is_signed && solid[o + i];
    const SliceBuffers<V>& b = buf[inside ? 1 : 0];
    const V cost = b.h[o + i];
    SiteOffset so;
    if (cost < inf && cost <= clamp) {
      const std::int32_t ys = b.arg_y[o + i];
      const std::int32_t xs = b.arg_x[static_cast<std::size_t>(ys) * width + x];
      so.dx = static_cast<std::int16_t>(xs - x);
      so.dy = static_cast<std::int16_t>(ys - y);
      // A column voxel that is itself a site of this transform (solid for the distance to solid,
      // air for the distance to air) stored the other transform's dz: its own is 0.
      const std::size_t col = static_cast<std::size_t>(ys) * width + xs;
      const bool column_is_site = is_signed ? (solid[col] != 0) != inside : solid[col] != 0;
      so.dz = column_is_site ? std::int16_t{0} : dz[col];
    }
    sites[i] = so;
  }
}

// Distances of `count` solved costs of one slice row into a caller's dense array (`stride`
// elements apart): the square root of the cost for Euclidean fields (`euclid`; costs are squared
// distances), the cost itself otherwise, `none` (the clamp, or +inf unclamped) where no site is
// within the clamp (a cost of `inf` or more, or above `clamp`). Signed fields pass the solid
// voxels' costs to air in f1 and which voxels are solid in `solid`: those read negated. The
// square root is taken in double: an integer squared distance gives the correctly rounded
// distance, as SciPy's.
template <class V, class Out>
void write_dense_row(const V* f0, const V* f1, const std::uint8_t* solid, V inf, V clamp,
                     bool euclid, double none, int count, Out* out, std::ptrdiff_t stride) {
  const auto distance = [inf, clamp, euclid, none](V c) {
    const double v = static_cast<double>(c);
    return c < inf && c <= clamp ? (euclid ? std::sqrt(v) : v) : none;
  };
  if (f1 == nullptr) {
    if (stride == 1) {
      for (int i = 0; i < count; ++i) out[i] = static_cast<Out>(distance(f0[i]));
    } else {
      for (int i = 0; i < count; ++i) out[i * stride] = static_cast<Out>(distance(f0[i]));
    }
    return;
  }
  for (int i = 0; i < count; ++i) {
    const bool inside = solid[i] != 0;
    const double d = distance(inside ? f1[i] : f0[i]);
    out[i * stride] = static_cast<Out>(inside ? -d : d);
  }
}

// One row of a slice into TruncatedMinConvolution's inputs: g (voxels along z, `cap` or more for
// none) becomes its square; signed fields split it into the distance to solid (f0, for air
// voxels) and to air (f1, for solid ones) and note which voxels are solid in `solid`.
template <class G>
void gather_truncated_row(const G* g, const std::uint8_t* world, int count, std::uint32_t cap,
                          bool is_signed, TruncatedMinConvolution::Cost* f0,
                          TruncatedMinConvolution::Cost* f1, std::uint8_t* solid) {
  using Cost = TruncatedMinConvolution::Cost;
  if (!is_signed) {
    for (int i = 0; i < count; ++i)
      f0[i] = g[i] < cap ? static_cast<Cost>(g[i] * g[i]) : TruncatedMinConvolution::kInf;
    return;
  }
  for (int i = 0; i < count; ++i) {
    const Cost c = g[i] < cap ? static_cast<Cost>(g[i] * g[i]) : TruncatedMinConvolution::kInf;
    const bool s = world[i] != 0;
    if (solid) solid[i] = s;
    f1[i] = s ? c : Cost{0};  // distance to air
    f0[i] = s ? Cost{0} : c;  // distance to solid
  }
}

// Encodes `count` solved costs of row y from column x0 of `conv` (conv[1] for the solid voxels
// of signed fields, `solid` giving them) into `out`.
template <class T>
void encode_truncated_row(const Encoder<T>& encoder, const TruncatedMinConvolution* conv, int y,
                          int x0, int count, const std::uint8_t* solid, T* out,
                          TruncatedMinConvolution::Cost drop) {
  using Conv = TruncatedMinConvolution;
  if (encoder.row_path) {
    encoder.encode_row(conv[0].out_row(y) + x0, out, count, Conv::kInf, drop);
    return;
  }
  for (int i = 0; i < count; ++i) {
    const bool inside = encoder.p.is_signed && solid[i];
    const Conv::Cost cost = conv[inside ? 1 : 0].out_row(y)[x0 + i];
    out[i] = encoder.encode(static_cast<double>(cost), cost < Conv::kInf, inside);
  }
}

}  // namespace voxfield::detail::exact
