// voxfield — pass A of the exact transform, along z (internal): for every voxel, g = the distance
// in voxels to the nearest site of its column (x, y, *), by a forward and a backward sweep
// (Meijster, Roerdink & Hesselink, "A general algorithm for computing distance transforms in
// linear time", 2000, phase 1; here on whole rows of voxels at once, so that the lanes vectorise).
//
// Two drivers share the sweep step: pass_z runs on the chunk rows of a whole field and stores g
// in the output chunks; region_pass_z runs on a dense box for local recomputation and keeps g for
// the output slices only. Both also find, when asked, the z offset of each voxel's nearest column
// site (below wins ties), from which the slice passes complete the nearest-site offsets.
//
// Signed fields need two transforms (to solid and to air) but only one g per voxel: a solid
// voxel's distance to the nearest solid is 0 and an air voxel's distance to the nearest air is 0,
// so each voxel keeps the one that is not trivially zero. A g at or beyond `cap` (the clamp's
// reach along z, plus one) is "none": any site reached through it is farther than the clamp.
#pragma once

#include <algorithm>
#include <climits>
#include <cstdint>
#include <limits>
#include <vector>

#include "chunk_rows.h"
#include "voxfield/detail/vector_clones.h"

namespace voxfield::detail::exact {

// For a slab of a larger domain (distance_slab.h): per column of the domain's x-y extent, the z of
// the nearest solid and air voxel below the slab (INT32_MIN / 2 when none) and above it
// (INT32_MAX / 2 when none). The sweeps start from them instead of from "nothing seen".
struct ColumnsBeyond {
  const std::int32_t* solid_below = nullptr;
  const std::int32_t* air_below = nullptr;
  const std::int32_t* solid_above = nullptr;
  const std::int32_t* air_above = nullptr;
};

// One step of a z sweep over `n` lanes: ds / da are the running distances (in voxels) to the
// nearest solid / air voxel seen so far, saturating at cap; returns through `c` the one each voxel
// stores (for signed fields the distance that is not trivially zero). Shared by the whole-field
// and the local passes.
// G: the lane type (32 bits in general; 8 bits when cap fits, for four times the lanes per step).
template <bool kSigned, class G = std::uint32_t>
inline void z_sweep_step(const std::uint8_t* __restrict w, G* __restrict ds, G* __restrict da,
                         G* __restrict c, std::size_t n, G cap) {
  for (std::size_t i = 0; i < n; ++i) {
    const bool solid = w[i] != 0;
    ds[i] = solid ? G{0} : std::min(static_cast<G>(ds[i] + 1u), cap);
    if constexpr (kSigned) {
      da[i] = solid ? std::min(static_cast<G>(da[i] + 1u), cap) : G{0};
      c[i] = solid ? da[i] : ds[i];
    } else {
      c[i] = ds[i];
    }
  }
}

// Pass A on one chunk column (cx, cy) of the domain: for rows y in the domain, sweep z up and down
// over `edge` lanes along x at once. The column of a row (Z x edge values) lives in `col`, a
// thread-local buffer small enough for the cache, so each output voxel is written exactly once.
// U: the unsigned integer the output storage holds g in; g >= cap is stored as kInf ("none").
// `beyond`, when given, holds the sites of the columns outside the domain's z range.
// (Twice: in AVX2 too, vector_clones.h — the sweeps are lanes of integer min and add, twice as
// many per instruction; with the slice passes' copies, 10-14 % off one thread's Manhattan
// transform.)
template <class U, bool kSigned>
VOXFIELD_AVX2_CLONE void pass_z(const Plan& p, const SolidRows& world, ChunkedVolume<U>& g,
                                ChunkedVolume<SiteOffset>* sites, int cx, int cy, std::uint32_t cap,
                                std::vector<std::uint32_t>& col,
                                const ColumnsBeyond* beyond = nullptr) {
  constexpr U kInf = std::numeric_limits<U>::max();
  const int e = g.edge;
  const int y0 = std::max(p.domain.begin.y, g.box.begin.y + cy * e);
  const int y1 = std::min(p.domain.end.y, g.box.begin.y + (cy + 1) * e);
  const int z0 = p.domain.begin.z, z1 = p.domain.end.z;
  col.resize(static_cast<std::size_t>(z1 - z0) * e);
  std::uint32_t ds[128], da[128];
  std::int32_t ls[128], la[128];  // z of the last solid / air site seen (sites only)
  const int x0 = g.box.begin.x + cx * e;
  // The lanes of this chunk column inside the domain: only those are stored. The others belong to
  // voxels outside the domain, which keep the background the driver filled them with (passes B
  // and C never revisit them; pass A's raw g there read as NaN or as a tiny distance in f32).
  const int i_lo = std::max(0, p.domain.begin.x - x0), i_hi = std::min(e, p.domain.end.x - x0);
  // Lane i's column index into `beyond`, or -1 outside the domain (or without `beyond`).
  auto column = [&](int y, int i) -> std::int64_t {
    const int x = x0 + i;
    if (!beyond || x < p.domain.begin.x || x >= p.domain.end.x) return -1;
    return static_cast<std::int64_t>(y - p.domain.begin.y) * p.domain.size().x +
           (x - p.domain.begin.x);
  };
  // The running distance (in voxels, capped) just before the sweep enters the domain, from the
  // nearest site beyond it: `from` sits `dist(from)` voxels before the first voxel minus one.
  auto start = [&](std::uint32_t* d, const std::int32_t* from, int y, bool upward) {
    if (!beyond) {  // one process's whole field: nothing beyond the domain
      std::fill_n(d, e, cap);
      return;
    }
    for (int i = 0; i < e; ++i) {
      const std::int64_t c = column(y, i);
      // No site beyond (the sentinels of start_sites below): nothing seen yet.
      if (c < 0 || from[c] == (upward ? INT32_MIN / 2 : INT32_MAX / 2)) {
        d[i] = cap;
        continue;
      }
      const std::int64_t dist =
          upward ? std::int64_t{z0} - 1 - from[c] : from[c] - std::int64_t{z1};
      d[i] = static_cast<std::uint32_t>(std::min<std::int64_t>(dist, cap));
    }
  };
  auto start_sites = [&](std::int32_t* l, const std::int32_t* from, int y, std::int32_t none) {
    if (!beyond) {
      std::fill_n(l, e, none);
      return;
    }
    for (int i = 0; i < e; ++i) {
      const std::int64_t c = column(y, i);
      l[i] = c < 0 ? none : from[c];
    }
  };
  for (int y = y0; y < y1; ++y) {
    // Forward (increasing z): distance to the nearest site at or below.
    start(ds, beyond ? beyond->solid_below : nullptr, y, true);
    start(da, beyond ? beyond->air_below : nullptr, y, true);
    // __restrict: the rows never alias, and saying so lets the compiler vectorise the lanes.
    std::uint32_t* __restrict dsr = ds;
    std::uint32_t* __restrict dar = da;
    for (int z = z0; z < z1; ++z) {
      z_sweep_step<kSigned>(world.row(cx, y, z), dsr, dar,
                            col.data() + static_cast<std::size_t>(z - z0) * e,
                            static_cast<std::size_t>(e), cap);
    }
    // Backward (decreasing z): keep the smaller, and store once.
    start(ds, beyond ? beyond->solid_above : nullptr, y, false);
    start(da, beyond ? beyond->air_above : nullptr, y, false);
    for (int z = z1 - 1; z >= z0; --z) {
      const std::uint8_t* __restrict w = world.row(cx, y, z);
      const std::uint32_t* __restrict c = col.data() + static_cast<std::size_t>(z - z0) * e;
      U* __restrict out = g.row(cx, y, z);
      for (int i = i_lo; i < i_hi; ++i) {
        const bool solid = w[i] != 0;
        dsr[i] = solid ? 0u : std::min(dsr[i] + 1u, cap);
        std::uint32_t v;
        if constexpr (kSigned) {
          dar[i] = solid ? std::min(dar[i] + 1u, cap) : 0u;
          v = std::min(c[i], solid ? dar[i] : dsr[i]);
        } else {
          v = std::min(c[i], dsr[i]);
        }
        out[i] = v >= cap ? kInf : static_cast<U>(v);
      }
    }
    if (!sites) continue;
    // Nearest site along z: below (found by the upward sweep) wins ties.
    start_sites(ls, beyond ? beyond->solid_below : nullptr, y, INT32_MIN / 2);
    start_sites(la, beyond ? beyond->air_below : nullptr, y, INT32_MIN / 2);
    for (int z = z0; z < z1; ++z) {
      const std::uint8_t* w = world.row(cx, y, z);
      SiteOffset* so = sites->row(cx, y, z);
      for (int i = i_lo; i < i_hi; ++i) {
        const bool solid = w[i] != 0;
        if (solid)
          ls[i] = z;
        else
          la[i] = z;
        so[i].dz = static_cast<std::int16_t>(
            std::clamp((kSigned && solid ? la[i] : ls[i]) - z, -32768, 32767));
      }
    }
    start_sites(ls, beyond ? beyond->solid_above : nullptr, y, INT32_MAX / 2);
    start_sites(la, beyond ? beyond->air_above : nullptr, y, INT32_MAX / 2);
    for (int z = z1 - 1; z >= z0; --z) {
      const std::uint8_t* w = world.row(cx, y, z);
      SiteOffset* so = sites->row(cx, y, z);
      for (int i = i_lo; i < i_hi; ++i) {
        const bool solid = w[i] != 0;
        if (solid)
          ls[i] = z;
        else
          la[i] = z;
        const std::int32_t above = (kSigned && solid ? la[i] : ls[i]) - z;  // >= 0
        const std::int32_t below = -static_cast<std::int32_t>(so[i].dz);    // >= 0 when found
        if (above < below) so[i].dz = static_cast<std::int16_t>(std::min(above, 32767));
      }
    }
  }
}

// G: the type g is kept in (8 bits when cap < 256, see z_sweep_step); dz only with 32 bits.
template <bool kSigned, class G>
void region_pass_z(const std::uint8_t* solid, Vec3i n, int z0, int z1, G cap, G* g,
                   std::int16_t* dz) {
  const std::size_t nx = static_cast<std::size_t>(n.x), plane = nx * static_cast<std::size_t>(n.y);
  thread_local std::vector<G> col_scratch, ds_scratch,
      da_scratch;  // kept per thread: see local_region.cpp
  std::vector<G>& col = col_scratch;
  std::vector<G>& ds = ds_scratch;
  std::vector<G>& da = da_scratch;
  col.resize(static_cast<std::size_t>(n.z) * nx);
  ds.resize(nx);
  da.resize(nx);
  std::vector<std::int32_t> ls(dz ? nx : 0), la(dz ? nx : 0);
  for (int y = 0; y < n.y; ++y) {
    G* __restrict dsr = ds.data();
    G* __restrict dar = da.data();
    std::fill(ds.begin(), ds.end(), cap);
    std::fill(da.begin(), da.end(), cap);
    for (int z = 0; z < n.z; ++z) {
      z_sweep_step<kSigned, G>(
          solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx, dsr, dar,
          col.data() + static_cast<std::size_t>(z) * nx, nx, cap);
    }
    std::fill(ds.begin(), ds.end(), cap);
    std::fill(da.begin(), da.end(), cap);
    for (int z = n.z - 1; z >= z0; --z) {
      const std::uint8_t* __restrict w =
          solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx;
      const G* __restrict c = col.data() + static_cast<std::size_t>(z) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        const bool s = w[i] != 0;
        dsr[i] = s ? G{0} : std::min(static_cast<G>(dsr[i] + 1u), cap);
        if constexpr (kSigned) dar[i] = s ? std::min(static_cast<G>(dar[i] + 1u), cap) : G{0};
      }
      if (z >= z1) continue;
      G* __restrict out =
          g + static_cast<std::size_t>(z - z0) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        const G back = (kSigned && w[i] != 0) ? dar[i] : dsr[i];
        out[i] = std::min(c[i], back);
      }
    }
    if (!dz) continue;
    // Nearest site along z, below winning ties, for the slices of `out`.
    std::fill(ls.begin(), ls.end(), INT32_MIN / 2);
    std::fill(la.begin(), la.end(), INT32_MIN / 2);
    for (int z = 0; z < z1; ++z) {
      const std::uint8_t* w =
          solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) (w[i] != 0 ? ls[i] : la[i]) = z;
      if (z < z0) continue;
      std::int16_t* d =
          dz + static_cast<std::size_t>(z - z0) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        d[i] = static_cast<std::int16_t>(
            std::clamp((kSigned && w[i] != 0 ? la[i] : ls[i]) - z, -32768, 32767));
      }
    }
    std::fill(ls.begin(), ls.end(), INT32_MAX / 2);
    std::fill(la.begin(), la.end(), INT32_MAX / 2);
    for (int z = n.z - 1; z >= z0; --z) {
      const std::uint8_t* w =
          solid + static_cast<std::size_t>(z) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) (w[i] != 0 ? ls[i] : la[i]) = z;
      if (z >= z1) continue;
      std::int16_t* d =
          dz + static_cast<std::size_t>(z - z0) * plane + static_cast<std::size_t>(y) * nx;
      for (std::size_t i = 0; i < nx; ++i) {
        const std::int32_t above = (kSigned && w[i] != 0 ? la[i] : ls[i]) - z;
        if (above < -static_cast<std::int32_t>(d[i]))
          d[i] = static_cast<std::int16_t>(std::min(above, 32767));
      }
    }
  }
}

}  // namespace voxfield::detail::exact
