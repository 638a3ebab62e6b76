// voxfield — exact distance transforms of whole fields (Manhattan, Chebyshev, Euclidean; signed;
// clamped; nearest sites) by separable passes: compute_distance_field.
//
// Meijster, Roerdink & Hesselink, "A general algorithm for computing distance transforms in linear
// time" (2000), with the line kernels in ../line_transforms.h. The passes run in this order:
//
//  A. along z, per column (z_pass.h): g(x,y,z) = distance in voxels to the nearest site in the
//     column (x, y, *). Runs on rows of chunk-edge voxels along x at once (vectorisable), and
//     stores g in the output chunks themselves, so no volume-sized scratch is needed (peak memory
//     beyond input and output is a few slices).
//  B. along x and C. along y, per z-slice (slice_solvers.h): a slice only needs its own g values,
//     so each slice is gathered into thread-local buffers, solved in 2-D, and written back in
//     place as final values (slice_io.h, shared with local recomputation: local_region.cpp).
//
// With a clamp D, a g whose contribution alone exceeds D is dropped as "none": any site reached
// through it is farther than D, so the clamped result is unchanged. This also lets integer
// storage hold g in place when the clamp (explicit, or implied by the type's range) fits.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "chunk_rows.h"
#include "encoder.h"
#include "slice_io.h"
#include "slice_solvers.h"
#include "voxfield/distance.h"
#include "voxfield/interrupt.h"
#include "voxfield/parallel.h"
#include "whole_field.h"
#include "z_pass.h"

namespace voxfield {
namespace {

using detail::TruncatedMinConvolution;
using detail::exact::ChunkedVolume;
using detail::exact::ColumnsBeyond;
using detail::exact::dispatch_solver;
using detail::exact::encode_truncated_row;
using detail::exact::Encoder;
using detail::exact::for_each_row_segment;
using detail::exact::gather_row;
using detail::exact::gather_truncated_row;
using detail::exact::pass_z;
using detail::exact::Plan;
using detail::exact::SliceBuffers;
using detail::exact::SliceCosts;
using detail::exact::SolidRows;
using detail::exact::truncated_passes;
using detail::exact::write_dense_row;
using detail::exact::write_row;

// Passes B and C of the whole field, slice by slice, through a solver of slice_solvers.h: each
// slice's g is gathered from the chunk rows and solved, and `store(z, buf, solid, dz)` writes its
// results (buf[0].h, buf[1].h for the solid voxels of signed fields, row-major) where they go.
template <class U, class V, class Solve, class Store>
void pass_slices(const Plan& p, const SolidRows& world, ChunkedVolume<U>& g,
                 ChunkedVolume<SiteOffset>* sites, const Solve& solve, const SliceCosts<V>& costs,
                 std::uint32_t cap_vox, Progress& progress, const Store& store) {
  constexpr U kInfU = std::numeric_limits<U>::max();
  const int X = p.domain.size().x, Y = p.domain.size().y;
  const int by = p.domain.begin.y;
  const U cap_u = static_cast<U>(std::min<std::uint64_t>(cap_vox, kInfU));
  const int passes = p.is_signed ? 2 : 1;
  // Ranges of several slices each, so that the buffers are allocated a few times per thread only.
  const std::size_t Z = static_cast<std::size_t>(p.domain.size().z);
  const std::size_t grain =
      std::max<std::size_t>(1, Z / (4 * static_cast<std::size_t>(max_threads())));
  parallel_for(Z, grain, [&](std::size_t zb, std::size_t ze) {
    SliceBuffers<V> buf[2];
    std::vector<std::uint8_t> solid(static_cast<std::size_t>(X) * Y);
    std::vector<std::int16_t> dz(sites ? static_cast<std::size_t>(X) * Y : 0);
    for (int k = 0; k < passes; ++k) buf[k].resize(X, Y);
    for (std::size_t zi = zb; zi < ze; ++zi) {
      if (!progress.advance()) return;  // one unit per slice (counted as it starts)
      const int z = p.domain.begin.z + static_cast<int>(zi);
      for (int y = 0; y < Y; ++y) {
        for_each_row_segment(p, g.edge, g.shift, [&](int cx, int lx, int count, int xo) {
          const std::size_t o = static_cast<std::size_t>(y) * X + xo;
          gather_row(costs, g.row(cx, by + y, z) + lx, cap_u, world.row(cx, by + y, z) + lx, count,
                     buf[0].f.data() + o, p.is_signed ? buf[1].f.data() + o : nullptr,
                     p.is_signed || sites ? solid.data() + o : nullptr);
          if (sites) {
            const SiteOffset* ss = sites->row(cx, by + y, z) + lx;
            for (int i = 0; i < count; ++i) dz[o + i] = ss[i].dz;
          }
        });
      }
      for (int k = 0; k < passes; ++k) solve(X, Y, buf[k], 0, X);
      store(z, static_cast<const SliceBuffers<V>*>(buf), solid.data(), dz.data());
    }
  });
}

// Passes B and C and encoding of a whole field through TruncatedMinConvolution: pass_slices'
// work, slice by slice, with the window the whole slice.
// `store(z, conv, solid)` writes a solved slice (conv[1] for the solid voxels of signed fields).
template <class U, class Store>
void pass_slices_truncated(const Plan& p, const SolidRows& world, ChunkedVolume<U>& g,
                           std::uint32_t cap, Progress& progress, const Store& store) {
  using Conv = TruncatedMinConvolution;
  const int X = p.domain.size().x, Y = p.domain.size().y;
  const int by = p.domain.begin.y;
  const int reach = static_cast<int>(std::floor(p.clamp));
  const auto drop = static_cast<Conv::Cost>(std::floor(p.clamp * p.clamp));
  const int passes = p.is_signed ? 2 : 1;
  const std::size_t Z = static_cast<std::size_t>(p.domain.size().z);
  const std::size_t grain =
      std::max<std::size_t>(1, Z / (4 * static_cast<std::size_t>(max_threads())));
  parallel_for(Z, grain, [&](std::size_t zb, std::size_t ze) {
    Conv conv[2];
    std::vector<std::uint8_t> solid(p.is_signed ? static_cast<std::size_t>(X) * Y : 0);
    for (int k = 0; k < passes; ++k) conv[k].prepare(X, Y, 0, 0, X, Y, reach, drop);
    for (std::size_t zi = zb; zi < ze; ++zi) {
      if (!progress.advance()) return;  // one unit per slice (counted as it starts)
      const int z = p.domain.begin.z + static_cast<int>(zi);
      for (int y = 0; y < Y; ++y) {
        for_each_row_segment(p, g.edge, g.shift, [&](int cx, int lx, int count, int xo) {
          const std::size_t o = static_cast<std::size_t>(y) * X + xo;
          gather_truncated_row(g.row(cx, by + y, z) + lx, world.row(cx, by + y, z) + lx, count, cap,
                               p.is_signed, conv[0].f_row(y) + xo,
                               p.is_signed ? conv[1].f_row(y) + xo : nullptr,
                               p.is_signed ? solid.data() + o : nullptr);
        });
      }
      for (int k = 0; k < passes; ++k) conv[k].solve();
      store(z, static_cast<const Conv*>(conv), solid.data());
    }
  });
}

// Largest g worth keeping, in voxels along z: beyond it a column's site is farther than the clamp.
template <class U>
std::uint32_t g_cap(const Plan& p) {
  constexpr std::uint64_t kInfU = std::numeric_limits<U>::max();
  std::uint64_t cap = kInfU;
  if (std::isfinite(p.clamp)) {
    const double vox = std::floor(p.clamp / p.spacing[2]) + 1;
    cap = static_cast<std::uint64_t>(std::min<double>(vox, static_cast<double>(kInfU)));
  }
  return static_cast<std::uint32_t>(
      std::min<std::uint64_t>(cap, std::numeric_limits<std::uint32_t>::max() - 1));
}

// Pass A over every chunk column of the domain, into g (and the sites' z offsets).
template <class U>
void pass_a(const Plan& p, const SolidRows& world, ChunkedVolume<U>& g,
            ChunkedVolume<SiteOffset>* sites, std::uint32_t cap, const ColumnsBeyond* beyond,
            Progress& progress) {
  const int ncx = g.nchunks.x;
  parallel_for(static_cast<std::size_t>(ncx) * g.nchunks.y, 1, [&](std::size_t b, std::size_t e) {
    std::vector<std::uint32_t> col;
    for (std::size_t i = b; i < e; ++i) {
      if (!progress.advance()) return;  // one unit per chunk column
      const int cx = static_cast<int>(i % ncx), cy = static_cast<int>(i / ncx);
      if (p.is_signed) {
        pass_z<U, true>(p, world, g, sites, cx, cy, cap, col, beyond);
      } else {
        pass_z<U, false>(p, world, g, sites, cx, cy, cap, col, beyond);
      }
    }
  });
}

std::int64_t progress_units(const Plan& p, Vec3i nchunks) {
  return static_cast<std::int64_t>(nchunks.x) * nchunks.y + p.domain.size().z;
}

// The whole field of storage T, g held in place in U (T's size) between the passes.
template <class T, class U>
DistanceField compute_whole_field(const Grid<std::uint8_t>& occupancy,
                                  const DistanceOptions& options, const Plan& p,
                                  const ColumnsBeyond* beyond, Vec3i solver_extent) {
  const T background = detail::field_background<T>(p);
  DistanceField out;
  out.options = options;
  out.options.interrupter = nullptr;  // the field never keeps a pointer to the caller's interrupter
  out.domain = p.domain;
  out.encoding = p.encoding;
  const int edge = occupancy.chunk_edge();
  Grid<T> values(edge, background, occupancy.bounds());
  std::optional<Grid<SiteOffset>> sites_grid;
  if (p.sites) sites_grid.emplace(edge, SiteOffset{}, occupancy.bounds());
  if (p.domain.empty()) {
    out.values = std::move(values);
    out.sites = std::move(sites_grid);
    return out;
  }

  ChunkedVolume<U> g(p.aligned, edge);
  std::optional<ChunkedVolume<SiteOffset>> sites;
  if (p.sites) sites.emplace(p.aligned, edge);
  ChunkedVolume<SiteOffset>* sp = sites ? &*sites : nullptr;
  const SolidRows world(occupancy, p.aligned);

  // Chunks reaching outside the domain keep the background there.
  {
    U bg;
    std::memcpy(&bg, &background, sizeof(U));
    const std::size_t volume = std::size_t{1} << (3 * g.shift);
    parallel_for(g.chunks.size(), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const Vec3i lo{g.coords[i].x * edge, g.coords[i].y * edge, g.coords[i].z * edge};
        if (!p.domain.contains(Box3i{lo, lo + Vec3i::splat(edge)})) {
          std::fill(g.chunks[i].get(), g.chunks[i].get() + volume, bg);
          if (sites)
            std::fill(sites->chunks[i].get(), sites->chunks[i].get() + volume, SiteOffset{});
        }
      }
    });
  }

  const std::uint32_t cap = g_cap<U>(p);
  Progress progress(options.interrupter, "exact distance field", progress_units(p, g.nchunks));
  pass_a(p, world, g, sp, cap, beyond, progress);

  // Passes B and C, and encoding: each slice's values are written back into its own chunk rows.
  const Encoder<T> encoder(p);
  const int X = p.domain.size().x, Y = p.domain.size().y, by = p.domain.begin.y;
  if (truncated_passes(p, p.sites)) {
    using Conv = TruncatedMinConvolution;
    const auto drop = static_cast<Conv::Cost>(std::floor(p.clamp * p.clamp));
    pass_slices_truncated(
        p, world, g, cap, progress, [&](int z, const Conv* conv, const std::uint8_t* solid) {
          for (int y = 0; y < Y; ++y) {
            for_each_row_segment(p, edge, g.shift, [&](int cx, int lx, int count, int xo) {
              // T and U have the same size.
              T* row = reinterpret_cast<T*>(g.row(cx, by + y, z)) + lx;
              encode_truncated_row(
                  encoder, conv, y, xo, count,
                  p.is_signed ? solid + static_cast<std::size_t>(y) * X + xo : nullptr, row, drop);
            });
          }
        });
  } else {
    dispatch_solver(p, solver_extent, [&](auto tag, const auto& solve, auto inf) {
      using V = decltype(tag);
      const SliceCosts<V> costs(p, inf);
      pass_slices(p, world, g, sp, solve, costs, cap, progress,
                  [&](int z, const SliceBuffers<V>* buf, const std::uint8_t* solid,
                      const std::int16_t* dz) {
                    for (int y = 0; y < Y; ++y) {
                      for_each_row_segment(
                          p, edge, g.shift, [&](int cx, int lx, int count, int xo) {
                            write_row(encoder, costs, buf, solid, dz, X, y, xo, count,
                                      reinterpret_cast<T*>(g.row(cx, by + y, z)) + lx,
                                      sp ? sp->row(cx, by + y, z) + lx : nullptr);
                          });
                    }
                  });
    });
  }
  progress.throw_if_cancelled();  // before anything is handed out

  // Hand the chunks to the grids (uniform ones collapse).
  std::vector<ChunkArray<T>> typed(g.chunks.size());
  for (std::size_t i = 0; i < g.chunks.size(); ++i)
    typed[i] = retype_chunk_array<T>(std::move(g.chunks[i]));
  values.adopt_chunks(g.coords, std::move(typed));
  if (sites) sites_grid->adopt_chunks(sites->coords, std::move(sites->chunks));
  out.values = std::move(values);
  out.sites = std::move(sites_grid);
  return out;
}

// The whole field written into a caller's dense array: the same passes, g in chunks of 32-bit
// voxels that are freed (to the chunk cache) afterwards, each slice's distances decoded from its
// costs straight into the array (no field grid, no encoding, no second pass over the volume).
template <class Out>
void compute_whole_field_dense(const Grid<std::uint8_t>& occupancy, const DistanceOptions& options,
                               const Plan& p, const DenseDistances<Out>& out) {
  if (p.domain.empty()) return;
  using U = std::uint32_t;
  ChunkedVolume<U> g(p.aligned, occupancy.chunk_edge());
  const SolidRows world(occupancy, p.aligned);
  const std::uint32_t cap = g_cap<U>(p);
  Progress progress(options.interrupter, "exact distance field", progress_units(p, g.nchunks));
  pass_a<U>(p, world, g, nullptr, cap, nullptr, progress);

  const int X = p.domain.size().x, Y = p.domain.size().y;
  const double none = std::isfinite(p.clamp) ? p.clamp : std::numeric_limits<double>::infinity();
  const bool euclid = p.metric == Metric::kEuclidean;
  const auto row_at = [&](int z, int y) {
    return out.data + (static_cast<std::ptrdiff_t>(z - p.domain.begin.z) * out.stride[2] +
                       static_cast<std::ptrdiff_t>(y) * out.stride[1]);
  };
  if (truncated_passes(p, false)) {
    using Conv = TruncatedMinConvolution;
    const auto drop = static_cast<Conv::Cost>(std::floor(p.clamp * p.clamp));
    pass_slices_truncated(
        p, world, g, cap, progress, [&](int z, const Conv* conv, const std::uint8_t* solid) {
          for (int y = 0; y < Y; ++y)
            write_dense_row(conv[0].out_row(y), p.is_signed ? conv[1].out_row(y) : nullptr,
                            p.is_signed ? solid + static_cast<std::size_t>(y) * X : nullptr,
                            Conv::kInf, drop, true, none, X, row_at(z, y), out.stride[0]);
        });
  } else {
    dispatch_solver(p, p.domain.size(), [&](auto tag, const auto& solve, auto inf) {
      using V = decltype(tag);
      const SliceCosts<V> costs(p, inf);
      pass_slices(
          p, world, g, static_cast<ChunkedVolume<SiteOffset>*>(nullptr), solve, costs, cap,
          progress,
          [&](int z, const SliceBuffers<V>* buf, const std::uint8_t* solid, const std::int16_t*) {
            for (int y = 0; y < Y; ++y) {
              const std::size_t o = static_cast<std::size_t>(y) * X;
              write_dense_row(buf[0].h.data() + o, p.is_signed ? buf[1].h.data() + o : nullptr,
                              p.is_signed ? solid + o : nullptr, costs.inf, costs.clamp, euclid,
                              none, X, row_at(z, y), out.stride[0]);
            }
          });
    });
  }
  progress.throw_if_cancelled();
}

}  // namespace

namespace detail::exact {

DistanceField compute_exact_field(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o,
                                  const Plan& p, const ColumnsBeyond* beyond, Vec3i solver_extent) {
  switch (o.storage) {
    case Storage::kU8:
      return compute_whole_field<std::uint8_t, std::uint8_t>(occupancy, o, p, beyond,
                                                             solver_extent);
    case Storage::kU16:
      return compute_whole_field<std::uint16_t, std::uint16_t>(occupancy, o, p, beyond,
                                                               solver_extent);
    case Storage::kF32:
      return compute_whole_field<float, std::uint32_t>(occupancy, o, p, beyond, solver_extent);
  }
  throw InvalidArgument("unknown storage");
}

}  // namespace detail::exact

DistanceField compute_distance_field(const Grid<std::uint8_t>& occupancy,
                                     const DistanceOptions& o) {
  const Plan p = detail::make_field_plan(occupancy, o);
  return detail::exact::compute_exact_field(occupancy, o, p, nullptr, p.domain.size());
}

namespace {

template <class Out>
void compute_into(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o,
                  const DenseDistances<Out>& out) {
  if (o.nearest_sites)
    throw InvalidArgument(
        "compute_distance_field_into: nearest sites are not written into a dense array (use "
        "compute_distance_field)");
  if (out.data == nullptr) throw InvalidArgument("compute_distance_field_into: no output array");
  if (!o.domain && !occupancy.bounds())
    throw InvalidArgument(
        "compute_distance_field_into: give options.domain (or bounds to the grid): the array "
        "covers it");
  DistanceOptions values_only = o;
  values_only.storage = Storage::kF32;  // the plan's checks of integer storage do not apply
  const Plan p = detail::make_field_plan(occupancy, values_only);
  // Slices are written in parallel: two voxels at one element would race.
  const Vec3i n = p.domain.size();
  for (int axis = 0; axis < 3; ++axis)
    if (n[axis] > 1 && out.stride[static_cast<std::size_t>(axis)] == 0)
      throw InvalidArgument("compute_distance_field_into: stride 0 along an axis of " +
                            std::to_string(n[axis]) + " voxels");
  compute_whole_field_dense(occupancy, values_only, p, out);
}

}  // namespace

void compute_distance_field_into(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o,
                                 const DenseDistances<double>& out) {
  compute_into(occupancy, o, out);
}
void compute_distance_field_into(const Grid<std::uint8_t>& occupancy, const DistanceOptions& o,
                                 const DenseDistances<float>& out) {
  compute_into(occupancy, o, out);
}

}  // namespace voxfield
