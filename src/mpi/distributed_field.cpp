// voxfield — exact distance fields over the ranks of an MPI job (mpi.h).
//
// Meijster, Roerdink & Hesselink, "A general algorithm for computing distance transforms in linear
// time" (2000), split by z-slabs: the first pass runs along z and depends on the rest of a column
// only through its nearest site on either side, the later passes stay within a slice. So each rank
// finds its slab's extreme solid and air voxels per column (slab_column_sites), two exclusive scans
// over the ranks give every slab the nearest ones below it (the maximum of the highest below) and
// above it (the minimum of the lowest above, scanned over the ranks in reverse order), and each
// rank then runs the whole-field transform on its slab alone (compute_slab_distance_field). No halo
// of slices moves, whatever the clamp: 16 bytes per column and rank.
#include <chrono>

#include "collective.h"
#include "voxfield/distance_executor.h"
#include "voxfield/distance_slab.h"
#include "voxfield/mpi.h"

namespace voxfield::mpi {
namespace {

// An exclusive scan of `values` (count ints) over the ranks of `comm` with `op`; rank 0 (which gets
// nothing from MPI) gets `none`. The output's room is agreed on first: a rank that cannot allocate
// it fails every rank instead of leaving them in the scan.
void exclusive_scan(MPI_Comm comm, std::vector<std::int32_t>& values, MPI_Op op, std::int32_t none,
                    ExchangeStats* stats) {
  std::vector<std::int32_t> out = detail::collectively(
      comm, stats, [&] { return std::vector<std::int32_t>(values.size(), none); });
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  {
    detail::CollectiveTimer t(stats);
    // MPI counts are ints: scan in pieces of at most 2^28 values.
    constexpr std::size_t kPiece = std::size_t{1} << 28;
    for (std::size_t at = 0; at < values.size(); at += kPiece) {
      const int n = static_cast<int>(std::min(kPiece, values.size() - at));
      MPI_Exscan(values.data() + at, out.data() + at, n, MPI_INT32_T, op, comm);
    }
  }
  if (rank == 0) std::fill(out.begin(), out.end(), none);
  if (stats) {
    int size = 1;
    MPI_Comm_size(comm, &size);
    const std::uint64_t bytes = values.size() * sizeof(std::int32_t);
    if (rank + 1 < size) stats->bytes_sent += bytes;  // the last rank's part reaches nobody
    if (rank > 0) stats->bytes_received += bytes;
  }
  values.swap(out);
}

// Every rank's neighbours beyond its slab: its own extremes, packed for the two scans — [highest
// solid | highest air] and [lowest solid | lowest air] — then scanned over the ranks below it and
// (in reverse order) above it. The packed arrays die before the transform: at 8192^2 columns each
// is half a gigabyte.
SlabNeighbours exchange_neighbours(MPI_Comm comm, const SlabPartition& partition,
                                   const Grid<std::uint8_t>& occupancy, ExchangeStats* stats) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const auto t0 = std::chrono::steady_clock::now();
  SlabNeighbours neighbours;
  std::vector<std::int32_t> below, above;
  detail::collectively(comm, stats, [&] {
    detail::require_partition(comm, partition);
    const Box3i slab = partition.slab(rank);
    ColumnSites own = slab_column_sites(occupancy, partition.domain, slab.begin.z, slab.end.z);
    below = std::move(own.highest_solid);
    below.insert(below.end(), own.highest_air.begin(), own.highest_air.end());
    above = std::move(own.lowest_solid);
    above.insert(above.end(), own.lowest_air.begin(), own.lowest_air.end());
  });
  if (stats) stats->compute_ms += detail::ms_since(t0);
  const std::size_t n = below.size() / 2;
  exclusive_scan(comm, below, MPI_MAX, ColumnSites::kNoneHigh, stats);
  // The slabs above: the same scan over the ranks in reverse order.
  MPI_Comm reversed = MPI_COMM_NULL;
  MPI_Comm_split(comm, 0, size - 1 - rank, &reversed);
  exclusive_scan(reversed, above, MPI_MIN, ColumnSites::kNoneLow, stats);
  MPI_Comm_free(&reversed);
  // (Agreed on too: a rank that cannot hold its neighbours would leave the others in the
  // transform's agreement.)
  detail::collectively(comm, stats, [&] {
    const auto half = static_cast<std::ptrdiff_t>(n);
    neighbours.solid_below.assign(below.begin(), below.begin() + half);
    neighbours.air_below.assign(below.begin() + half, below.end());
    neighbours.solid_above.assign(above.begin(), above.begin() + half);
    neighbours.air_above.assign(above.begin() + half, above.end());
  });
  return neighbours;
}

// This rank's slab from its neighbours, by `transform` (the CPU's or an executor's), failures
// agreed on.
template <class Transform>
DistanceField slab_field(MPI_Comm comm, const SlabPartition& partition,
                         const Grid<std::uint8_t>& occupancy, ExchangeStats* stats,
                         Transform&& transform) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const SlabNeighbours neighbours = exchange_neighbours(comm, partition, occupancy, stats);
  const auto t1 = std::chrono::steady_clock::now();
  DistanceField field = detail::collectively(comm, stats, [&] {
    const Box3i slab = partition.slab(rank);
    return transform(slab.begin.z, slab.end.z, neighbours);
  });
  if (stats) stats->compute_ms += detail::ms_since(t1);
  return field;
}

}  // namespace

DistanceField compute_distance_field(MPI_Comm comm, const SlabPartition& partition,
                                     const Grid<std::uint8_t>& occupancy,
                                     const DistanceOptions& options, ExchangeStats* stats) {
  DistanceOptions o = options;
  o.domain = partition.domain;
  return slab_field(comm, partition, occupancy, stats,
                    [&](std::int32_t z0, std::int32_t z1, const SlabNeighbours& n) {
                      return compute_slab_distance_field(occupancy, o, z0, z1, n);
                    });
}

DistanceField compute_distance_field(MPI_Comm comm, const SlabPartition& partition,
                                     const World& world, const DistanceOptions& options,
                                     const Executor& executor, ExchangeStats* stats) {
  DistanceOptions o = options;
  o.domain = partition.domain;
  return slab_field(comm, partition, world.voxels, stats,
                    [&](std::int32_t z0, std::int32_t z1, const SlabNeighbours& n) {
                      DistanceField f = compute_slab_distance_field(executor, world, o, z0, z1, n);
                      f.frame = world.frame;
                      return f;
                    });
}

}  // namespace voxfield::mpi
