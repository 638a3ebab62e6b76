// voxfield — exact field values of one box, for incremental updates: detail::compute_region.
//
// The same separable transform as whole fields (Meijster, Roerdink & Hesselink, "A general
// algorithm for computing distance transforms in linear time", 2000; whole_field.cpp), on a dense
// box. The values of a box `out` need only the sites within the clamp's reach of it, so they are
// computed on a dense box `in` (out grown by the reach): pass A over the columns of `in`, keeping
// g only for the slices of `out` (z_pass.h); the slice passes over `in`'s x-y extent for those
// slices, pass C on `out`'s columns only (slice_solvers.h); encoding of `out`'s part through the
// whole field's slice I/O (slice_io.h), so that both store the same values. Small clamps take
// truncated min-convolutions on the window alone (Felzenszwalb & Huttenlocher 2012). No chunk is
// allocated: the workspace is a few dense arrays of `in`'s size, kept per thread across calls.
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "../field_plan.h"
#include "encoder.h"
#include "slice_io.h"
#include "slice_solvers.h"
#include "voxfield/parallel.h"
#include "z_pass.h"

namespace voxfield::detail {
namespace {

using exact::encode_truncated_row;
using exact::Encoder;
using exact::gather_truncated_row;
using exact::Plan;
using exact::SliceBuffers;
using exact::SliceCosts;

// Slices of at most this many voxels run on the calling thread in ranges of about this size:
// handing ~10 slices of a small region to a pool costs more than computing them.
constexpr std::size_t kVoxelsPerTask = std::size_t{1} << 14;

// The solid voxels of `in` as a dense array (material bytes, x fastest), those outside
// `sites_within` (when given) counted as empty. The array is the calling thread's, kept across
// calls: incremental updates call this for every edit, and fresh allocations of this size come
// from mmap, paying a page fault per 4 KiB every time.
const std::vector<std::uint8_t>& dense_sites(const Grid<std::uint8_t>& occupancy, const Box3i& in,
                                             const Box3i* sites_within) {
  thread_local std::vector<std::uint8_t> solid;
  thread_local std::vector<std::uint8_t> part;
  solid.resize(static_cast<std::size_t>(in.volume()));
  const Box3i site_box = sites_within ? sites_within->intersect(in) : in;
  if (site_box == in) {
    occupancy.copy_to_dense(in, solid.data());
    return solid;
  }
  // Empty everywhere but the sites' box, copied row by row into place.
  std::fill(solid.begin(), solid.end(), std::uint8_t{0});
  if (site_box.empty()) return solid;
  part.resize(static_cast<std::size_t>(site_box.volume()));
  occupancy.copy_to_dense(site_box, part.data());
  const Vec3i n = in.size(), sn = site_box.size();
  for (int z = 0; z < sn.z; ++z)
    for (int y = 0; y < sn.y; ++y)
      std::copy_n(
          part.data() + (static_cast<std::size_t>(z) * sn.y + static_cast<std::size_t>(y)) * sn.x,
          sn.x,
          solid.data() +
              (static_cast<std::size_t>(site_box.begin.z - in.begin.z + z) * n.y +
               static_cast<std::size_t>(site_box.begin.y - in.begin.y + y)) *
                  n.x +
              static_cast<std::size_t>(site_box.begin.x - in.begin.x));
  return solid;
}

// The slice passes and encoding of compute_region_impl through TruncatedMinConvolution: for
// unit-spacing Euclidean fields without nearest sites whose clamp D is below kMaxReach + 1.
template <class T>
void region_slices_truncated(const Plan& p, const Encoder<T>& encoder, Vec3i n, const Box3i& out,
                             int ox, int oy, int z0, std::uint8_t cap, const std::uint8_t* solid,
                             const std::uint8_t* g, T* values) {
  using Conv = TruncatedMinConvolution;
  const Vec3i m = out.size();
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  const int reach = static_cast<int>(std::floor(p.clamp));  // |k| beyond it costs more than D²
  const auto drop = static_cast<Conv::Cost>(
      std::floor(p.clamp * p.clamp));  // integer costs above D² are beyond D
  const std::size_t grain = std::max<std::size_t>(1, kVoxelsPerTask / plane);
  parallel_for(static_cast<std::size_t>(m.z), grain, [&](std::size_t zb, std::size_t ze) {
    thread_local Conv kept[2];
    Conv* conv = kept;
    const int passes = p.is_signed ? 2 : 1;
    for (int k = 0; k < passes; ++k) conv[k].prepare(n.x, n.y, ox, oy, m.x, m.y, reach, drop);
    for (std::size_t zi = zb; zi < ze; ++zi) {
      const std::uint8_t* gs = g + zi * plane;
      const std::uint8_t* ws = solid + (static_cast<std::size_t>(z0) + zi) * plane;
      // `ws` already says which voxels are solid: no copy of it is needed.
      for (int y = 0; y < n.y; ++y)
        gather_truncated_row(gs + static_cast<std::size_t>(y) * n.x,
                             ws + static_cast<std::size_t>(y) * n.x, n.x, cap, p.is_signed,
                             conv[0].f_row(y), p.is_signed ? conv[1].f_row(y) : nullptr, nullptr);
      for (int k = 0; k < passes; ++k) conv[k].solve();
      for (int y = 0; y < m.y; ++y)
        encode_truncated_row(
            encoder, conv, y, 0, m.x,
            ws + static_cast<std::size_t>(y + oy) * n.x + static_cast<std::size_t>(ox),
            values + (zi * static_cast<std::size_t>(m.y) + static_cast<std::size_t>(y)) * m.x,
            drop);
    }
  });
}

// The slice passes and encoding of compute_region through a solver of slice_solvers.h: each
// slice of `out` gathered from `in`'s g (32 bits, `dz` its z offsets when sites are wanted),
// solved over `in`'s x-y extent and written through the slice I/O the whole field uses.
template <class T>
void region_slices_envelope(const Plan& p, const Encoder<T>& encoder, Vec3i n, const Box3i& out,
                            int ox, int oy, int z0, std::uint32_t cap_vox,
                            const std::uint8_t* solid, const std::uint32_t* g,
                            const std::int16_t* dz, T* values, SiteOffset* sites) {
  const Vec3i m = out.size();
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  exact::dispatch_solver(p, n, [&](auto tag, const auto& solve, auto inf) {
    using V = decltype(tag);
    const SliceCosts<V> costs(p, inf);
    const int passes = p.is_signed ? 2 : 1;
    const std::size_t grain = std::max<std::size_t>(1, kVoxelsPerTask / plane);
    parallel_for(static_cast<std::size_t>(m.z), grain, [&](std::size_t zb, std::size_t ze) {
      // Slice buffers of moderate size are kept per thread across calls (see dense_sites).
      thread_local SliceBuffers<V> kept[2];
      SliceBuffers<V> own[2];
      SliceBuffers<V>* buf = plane <= (std::size_t{1} << 16) ? kept : own;
      for (int k = 0; k < passes; ++k) buf[k].resize(n.x, n.y);
      for (std::size_t zi = zb; zi < ze; ++zi) {
        const std::uint32_t* gs = g + zi * plane;
        const std::uint8_t* ws = solid + (static_cast<std::size_t>(z0) + zi) * plane;
        // `ws` already says which voxels are solid: no copy of it is needed.
        for (int y = 0; y < n.y; ++y) {
          const std::size_t o = static_cast<std::size_t>(y) * n.x;
          exact::gather_row(costs, gs + o, cap_vox, ws + o, n.x, buf[0].f.data() + o,
                            p.is_signed ? buf[1].f.data() + o : nullptr, nullptr);
        }
        for (int k = 0; k < passes; ++k) solve(n.x, n.y, buf[k], ox, ox + m.x);
        for (int y = 0; y < m.y; ++y) {
          const std::size_t o =
              (zi * static_cast<std::size_t>(m.y) + static_cast<std::size_t>(y)) * m.x;
          exact::write_row(encoder, costs, buf, ws, sites ? dz + zi * plane : nullptr, n.x, y + oy,
                           ox, m.x, values + o, sites ? sites + o : nullptr);
        }
      }
    });
  });
}

template <class T>
void compute_region_impl(const Grid<std::uint8_t>& occupancy, const Plan& p, const Box3i& in,
                         const Box3i& out, T* values, SiteOffset* sites,
                         const Box3i* sites_within) {
  const Vec3i n = in.size(), m = out.size();
  const int z0 = out.begin.z - in.begin.z, z1 = out.end.z - in.begin.z;
  const int ox = out.begin.x - in.begin.x, oy = out.begin.y - in.begin.y;
  const std::size_t plane = static_cast<std::size_t>(n.x) * n.y;
  const std::uint8_t* solid = dense_sites(occupancy, in, sites_within).data();
  // Largest g worth keeping, in voxels: beyond it a column's site is farther than the clamp.
  std::uint64_t cap = std::numeric_limits<std::uint32_t>::max() - 1;
  if (std::isfinite(p.clamp))
    cap = std::min<std::uint64_t>(
        cap, static_cast<std::uint64_t>(std::floor(p.clamp / p.spacing[2]) + 1));
  const Encoder<T> encoder(p);
  // Scratch kept per thread across calls (see dense_sites).
  thread_local std::vector<std::uint8_t> g8;
  thread_local std::vector<std::uint32_t> g;
  thread_local std::vector<std::int16_t> dz;
  // Small clamps (the usual case for editable worlds), unit spacing, no nearest sites: the 2-D
  // passes as truncated min-convolutions on the window alone (truncated_min_convolution.h), and g
  // in 8-bit lanes (cap <= kMaxReach + 1).
  if (exact::truncated_passes(p, sites != nullptr)) {
    g8.resize(static_cast<std::size_t>(m.z) * plane);
    const auto cap8 = static_cast<std::uint8_t>(cap);
    if (p.is_signed) {
      exact::region_pass_z<true>(solid, n, z0, z1, cap8, g8.data(), nullptr);
    } else {
      exact::region_pass_z<false>(solid, n, z0, z1, cap8, g8.data(), nullptr);
    }
    region_slices_truncated(p, encoder, n, out, ox, oy, z0, cap8, solid, g8.data(), values);
    return;
  }
  const auto cap32 = static_cast<std::uint32_t>(cap);
  g.resize(static_cast<std::size_t>(m.z) * plane);
  dz.resize(sites ? g.size() : 0);
  if (p.is_signed) {
    exact::region_pass_z<true>(solid, n, z0, z1, cap32, g.data(), sites ? dz.data() : nullptr);
  } else {
    exact::region_pass_z<false>(solid, n, z0, z1, cap32, g.data(), sites ? dz.data() : nullptr);
  }
  region_slices_envelope(p, encoder, n, out, ox, oy, z0, cap32, solid, g.data(),
                         sites ? dz.data() : nullptr, values, sites);
}

}  // namespace

template <class T>
void compute_region(const Grid<std::uint8_t>& occupancy, const FieldPlan& p, const Box3i& in,
                    const Box3i& out, T* values, SiteOffset* sites, const Box3i* sites_within) {
  if (!in.contains(out))
    throw InvalidArgument("compute_region: the input box must contain the output box");
  if (out.empty()) return;
  compute_region_impl<T>(occupancy, p, in, out, values, sites, sites_within);
}
template void compute_region<std::uint8_t>(const Grid<std::uint8_t>&, const FieldPlan&,
                                           const Box3i&, const Box3i&, std::uint8_t*, SiteOffset*,
                                           const Box3i*);
template void compute_region<std::uint16_t>(const Grid<std::uint8_t>&, const FieldPlan&,
                                            const Box3i&, const Box3i&, std::uint16_t*, SiteOffset*,
                                            const Box3i*);
template void compute_region<float>(const Grid<std::uint8_t>&, const FieldPlan&, const Box3i&,
                                    const Box3i&, float*, SiteOffset*, const Box3i*);

}  // namespace voxfield::detail
