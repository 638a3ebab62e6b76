// voxfield — slabs of a domain for the ranks of an MPI job (mpi.h).
#include <algorithm>
#include <cmath>
#include <string>

#include "collective.h"
#include "voxfield/mpi.h"

namespace voxfield::mpi {

Box3i SlabPartition::slab(int rank) const {
  if (rank < 0 || rank >= ranks())
    throw InvalidArgument("rank " + std::to_string(rank) + " of a partition into " +
                          std::to_string(ranks()) + " slabs");
  return {{domain.begin.x, domain.begin.y, z[static_cast<std::size_t>(rank)]},
          {domain.end.x, domain.end.y, z[static_cast<std::size_t>(rank) + 1]}};
}

SlabPartition partition_slabs(const Box3i& domain, int ranks, int align) {
  if (ranks < 1) throw InvalidArgument("a partition needs at least one rank");
  if (align < 1) throw InvalidArgument("slab alignment must be at least one slice");
  if (domain.empty()) throw InvalidArgument("cannot split the empty domain " + to_string(domain));
  const std::int64_t slices = domain.size().z;
  if (slices < ranks)
    throw InvalidArgument("the domain " + to_string(domain) + " has " + std::to_string(slices) +
                          " slices along z, fewer than the " + std::to_string(ranks) +
                          " ranks (each rank owns at least one)");
  // Units of `align` slices, counted from the first multiple of align at or below the start: the
  // cuts fall on chunk boundaries when align is the chunk edge.
  const std::int64_t a = align;
  const std::int64_t base =
      (domain.begin.z >= 0 ? domain.begin.z / a : (domain.begin.z - a + 1) / a) * a;
  const std::int64_t units = (domain.end.z - base + a - 1) / a;
  SlabPartition p;
  p.domain = domain;
  p.z.resize(static_cast<std::size_t>(ranks) + 1);
  p.z.front() = domain.begin.z;
  p.z.back() = domain.end.z;
  // Whole units whenever every rank can have one: slabs then never share a chunk (a .vfw written by
  // every rank needs that), at the price of at most one unit of imbalance.
  const bool aligned = units >= ranks;
  for (int r = 1; r < ranks; ++r) {
    std::int64_t cut;
    if (aligned) {
      cut = base + (units * r / ranks) * a;  // whole units, as even as they divide
    } else {
      cut = domain.begin.z + slices * r / ranks;
    }
    p.z[static_cast<std::size_t>(r)] = static_cast<std::int32_t>(std::clamp<std::int64_t>(
        cut, p.z[static_cast<std::size_t>(r) - 1] + 1, domain.end.z - (ranks - r)));
  }
  return p;
}

std::vector<Box3i> slab_units(const Box3i& domain, int align) {
  if (align < 1) throw InvalidArgument("slab alignment must be at least one slice");
  std::vector<Box3i> units;
  if (domain.empty()) return units;
  const std::int64_t a = align;
  std::int64_t z = (domain.begin.z >= 0 ? domain.begin.z / a : (domain.begin.z - a + 1) / a) * a;
  for (; z < domain.end.z; z += a) {
    Box3i u = domain;
    u.begin.z = static_cast<std::int32_t>(std::max<std::int64_t>(z, domain.begin.z));
    u.end.z = static_cast<std::int32_t>(std::min<std::int64_t>(z + a, domain.end.z));
    units.push_back(u);
  }
  return units;
}

SlabPartition partition_slabs(const Box3i& domain, int ranks, int align,
                              const std::vector<double>& unit_weights) {
  SlabPartition p = partition_slabs(domain, ranks, align);
  const std::vector<Box3i> units = slab_units(domain, align);
  if (unit_weights.size() != units.size())
    throw InvalidArgument("partition_slabs: " + std::to_string(unit_weights.size()) +
                          " weights for the " + std::to_string(units.size()) + " units of " +
                          std::to_string(align) + " slices of " + to_string(domain));
  std::vector<double> prefix(units.size() + 1, 0.0);
  for (std::size_t k = 0; k < units.size(); ++k) {
    if (!(unit_weights[k] >= 0) || !std::isfinite(unit_weights[k]))
      throw InvalidArgument("partition_slabs: unit " + std::to_string(k) + "'s weight " +
                            std::to_string(unit_weights[k]) + " is not a finite weight >= 0");
    prefix[k + 1] = prefix[k] + unit_weights[k];
  }
  // Fewer units than ranks, or nothing weighed: the slabs of equal volume.
  if (units.size() < static_cast<std::size_t>(ranks) || !(prefix.back() > 0)) return p;
  // Each cut at the unit boundary where the running weight comes nearest its share, every rank
  // keeping at least one unit.
  std::size_t k = 0, previous = 0;  // the unit the previous rank's slab starts at
  for (int r = 1; r < ranks; ++r) {
    const double target = prefix.back() * r / ranks;
    while (k < units.size() && prefix[k + 1] <= target) ++k;
    if (k < units.size() && target - prefix[k] > prefix[k + 1] - target) ++k;
    k = std::clamp(k, previous + 1, units.size() - static_cast<std::size_t>(ranks - r));
    p.z[static_cast<std::size_t>(r)] = units[k].begin.z;
    previous = k;
  }
  return p;
}

std::vector<double> content_unit_weights(MPI_Comm comm, const SlabPartition& partition,
                                         const World& world, int align, ExchangeStats* stats) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::vector<double> counts = detail::collectively(comm, stats, [&] {
    detail::require_partition(comm, partition);
    const std::vector<Box3i> units = slab_units(partition.domain, align);
    std::vector<double> mine(units.size(), 0.0);
    if (units.empty()) return mine;
    const std::int64_t a = align;
    const std::int64_t begin = partition.domain.begin.z;
    const std::int64_t base = (begin >= 0 ? begin / a : (begin - a + 1) / a) * a;  // as slab_units
    const Box3i slab = partition.slab(rank);
    const Grid<std::uint8_t>& g = world.voxels;
    for (const Vec3i c : g.chunk_coords()) {
      const ChunkView<std::uint8_t> v = g.chunk_view(c);
      // A chunk is counted by the rank whose slab holds its first slice within the domain.
      const std::int32_t z = std::max(v.box.begin.z, partition.domain.begin.z);
      if (v.uniform() || z < slab.begin.z || z >= slab.end.z) continue;
      // A surface: air and solid both within the domain (a chunk of two materials is not one; the
      // voxels of an edge chunk past the domain are no one's).
      const Box3i in = v.box.intersect(partition.domain);
      const Vec3i e = v.box.size();
      std::int64_t air = 0;
      for (int vz = in.begin.z; vz < in.end.z; ++vz)
        for (int y = in.begin.y; y < in.end.y; ++y) {
          const std::uint8_t* row = v.voxels +
                                    (static_cast<std::size_t>(vz - v.box.begin.z) * e.y +
                                     static_cast<std::size_t>(y - v.box.begin.y)) *
                                        e.x +
                                    (in.begin.x - v.box.begin.x);
          air += std::count(row, row + (in.end.x - in.begin.x), 0);
        }
      if (air == 0 || air == in.volume()) continue;
      const std::int64_t k = (std::int64_t{z} - base) / a;
      if (k >= 0 && k < static_cast<std::int64_t>(mine.size()))
        mine[static_cast<std::size_t>(k)] += 1;
    }
    return mine;
  });
  {
    detail::CollectiveTimer t(stats);
    MPI_Allreduce(MPI_IN_PLACE, counts.data(), static_cast<int>(counts.size()), MPI_DOUBLE, MPI_SUM,
                  comm);
  }
  // Every chunk's field is computed: a 64th of each unit's chunks beside its surface.
  const Vec3i size = partition.domain.size();
  const double per_unit = std::ceil(static_cast<double>(size.x) / align) *
                          std::ceil(static_cast<double>(size.y) / align) / 64.0;
  for (double& c : counts) c += per_unit;
  return counts;
}

}  // namespace voxfield::mpi
