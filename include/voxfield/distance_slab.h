// voxfield — exact distance fields of one slab of a larger domain: the building block of fields
// computed by several processes (voxfield-mpi, mpi.h), each holding only its slab of the world.
//
// The exact transform (distance.h; Meijster, Roerdink & Hesselink 2000) runs its first pass along
// z, one column (x, y, *) at a time, and its other passes within z-slices. So a slab [z0, z1) of
// the domain needs from the rest of the domain only, for every column, the z of its nearest solid
// voxel below z0 and above z1 — and for signed fields of its nearest air voxel too: four numbers
// per column, whatever the clamp, instead of a halo of slices. Given them, the slab's values and
// nearest sites equal the whole-domain field's bit for bit, ties included (below wins along z, as
// in one process).
//
// The numbers come from the other slabs' ColumnSites: a process computes its own with
// slab_column_sites, and the nearest below its slab is the maximum of the `highest_*` of the slabs
// below it; the nearest above, the minimum of the `lowest_*` of the slabs above (kNoneLow and
// kNoneHigh are neutral for those reductions).
#pragma once

#include <cstdint>
#include <vector>

#include "voxfield/distance.h"

namespace voxfield {

// Per column of the domain's x-y extent (index (x - domain.begin.x) + X * (y - domain.begin.y)):
// the extreme z of the solid and of the air voxels of a slab.
struct ColumnSites {
  static constexpr std::int32_t kNoneLow = INT32_MAX / 2;   // no such voxel: lowest_*
  static constexpr std::int32_t kNoneHigh = INT32_MIN / 2;  // no such voxel: highest_*
  std::vector<std::int32_t> lowest_solid, highest_solid, lowest_air, highest_air;
};

// The extremes of the slab [z0, z1) of `domain` (solid = non-zero). The occupancy must hold the
// slab; voxels outside it are not read. Multi-threaded.
ColumnSites slab_column_sites(const Grid<std::uint8_t>& occupancy, const Box3i& domain,
                              std::int32_t z0, std::int32_t z1);

// Per column, the z of the nearest solid and air voxel of the domain outside the slab: below
// (kNoneHigh when none) and above (kNoneLow when none).
struct SlabNeighbours {
  std::vector<std::int32_t> solid_below, air_below, solid_above, air_above;
};

// The slab [z0, z1) of the exact field of the whole domain `options.domain` (required): the same
// values, encoding and nearest sites as compute_distance_field over the domain, for the slab's
// voxels, computed from the slab's own voxels of `occupancy` and `neighbours`. The returned
// field's domain is the slab. Options are checked against the whole domain (its extent bounds the
// nearest-site offsets); memory is checked for the slab. Throws InvalidArgument for a missing
// domain, a slab outside it, or neighbour arrays of the wrong size.
DistanceField compute_slab_distance_field(const Grid<std::uint8_t>& occupancy,
                                          const DistanceOptions& options, std::int32_t z0,
                                          std::int32_t z1, const SlabNeighbours& neighbours);

// The largest distance a field with these options stores — options.max_distance, or what its
// integer storage can hold (u8 Euclidean: 63.75) when that is less — or +inf for an unclamped f32
// field. A voxel's value depends only on the sites within it: how far apart the processes of a
// distributed field must share voxels for edits (mpi.h). Throws InvalidArgument as
// compute_distance_field does for bad options.
double effective_clamp(const DistanceOptions& options);

}  // namespace voxfield
