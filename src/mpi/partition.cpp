// voxfield — slabs of a domain for the ranks of an MPI job (mpi.h).
#include <algorithm>
#include <string>

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

}  // namespace voxfield::mpi
