// voxfield — a field the ranks hold in slabs written as one .vdb (mpi.h's encode_vdb_field).
//
// OpenVDB's trees are sparse and their leaves are 8-voxel cubes on multiples of 8. Each rank's grid
// holds the leaves and tiles of its own slab, and rank 0 moves every part's leaves and tiles into
// one tree (VdbFieldParts, vdb.h): slabs cut on chunk boundaries never split a leaf, and a leaf
// that slabs cut at single slices split (fewer chunk layers than ranks) is joined voxel by voxel.
// The final prune gives the tree the whole field's values give, and so the bytes one process
// writes. The background must be the whole field's before any part is
// encoded: an unclamped field's is its largest finite |distance|, a maximum over the ranks.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "collective.h"
#include "voxfield/mpi.h"
#include "voxfield/vdb.h"

namespace voxfield::mpi {

std::vector<std::uint8_t> encode_vdb_field(MPI_Comm comm, const SlabPartition& partition,
                                           const DistanceField& slab, ExchangeStats* stats) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const double own_background = detail::collectively(comm, stats, [&] {
    detail::require_partition(comm, partition);
    if (slab.domain != partition.slab(rank))
      throw InvalidArgument("this rank's field covers " + to_string(slab.domain) +
                            ", not exactly its slab " + to_string(partition.slab(rank)) +
                            " (a .vdb is written from each rank's slab)");
    return vdb_field_background(slab);
  });
  double background = 0;
  {
    detail::CollectiveTimer timer(stats);
    MPI_Allreduce(&own_background, &background, 1, MPI_DOUBLE, MPI_MAX, comm);
  }
  const Box3i& domain = partition.domain;
  std::optional<VdbFieldParts> joined;
  detail::collectively(comm, stats, [&] {
    if (rank == 0) joined.emplace(slab, background, domain);
  });
  for (int r = 1; r < size; ++r) {
    std::vector<std::uint8_t> part = detail::collectively(comm, stats, [&] {
      return rank == r ? encode_vdb_field_part(slab, background, domain)
                       : std::vector<std::uint8_t>{};
    });
    const std::string name = "rank " + std::to_string(r) + "'s part of the .vdb";
    part = detail::move_bytes(comm, r, 0, std::move(part), name, stats);
    detail::collectively(comm, stats, [&] {
      if (rank == 0) joined->add(part, name);
    });
  }
  return detail::collectively(
      comm, stats, [&] { return rank == 0 ? joined->finish() : std::vector<std::uint8_t>{}; });
}

}  // namespace voxfield::mpi
