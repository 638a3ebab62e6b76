// voxfield — a rank's slab of a world file (mpi.h): .npy arrays read a part per rank, other
// formats loaded whole by every rank.
#include <algorithm>

#include "collective.h"
#include "voxfield/npy.h"
#include "voxfield/world_io.h"

namespace voxfield::mpi {

WorldSlab load_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                          int ghost_slices) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  return detail::collectively(comm, nullptr, [&] {
    const WorldFormat format = world_format_of(path);
    if (format == WorldFormat::kNpy) {
      const NpyVolume head = read_npy_header(path);
      const SlabPartition partition =
          partition_slabs(Box3i::from_size(head.dims), size, chunk_edge);
      const Box3i slab = partition.slab(rank);
      const int ghost = std::max(ghost_slices, 0);
      const std::int32_t z0 =
          static_cast<std::int32_t>(std::max<std::int64_t>(0, std::int64_t{slab.begin.z} - ghost));
      const std::int32_t z1 = static_cast<std::int32_t>(
          std::min<std::int64_t>(head.dims.z, std::int64_t{slab.end.z} + ghost));
      World part = world_from_npy(read_npy_part(path, z0, z1), path.string(), chunk_edge);
      return WorldSlab{std::move(part), partition, "npy", true};
    }
    LoadOptions lo;
    lo.chunk_edge = chunk_edge;
    LoadedWorld whole = load_world(path, lo);
    if (whole.extent.empty()) throw InvalidArgument(path.string() + ": the input holds no volume");
    const SlabPartition partition = partition_slabs(whole.extent, size, chunk_edge);
    // Only the slab and its ghost slices are kept once the file is read.
    const Box3i slab = partition.slab(rank);
    const int ghost = std::max(ghost_slices, 0);
    const Box3i keep{{whole.extent.begin.x, whole.extent.begin.y,
                      static_cast<std::int32_t>(std::max<std::int64_t>(
                          whole.extent.begin.z, std::int64_t{slab.begin.z} - ghost))},
                     {whole.extent.end.x, whole.extent.end.y,
                      static_cast<std::int32_t>(std::min<std::int64_t>(
                          whole.extent.end.z, std::int64_t{slab.end.z} + ghost))}};
    World part = rechunk_world(whole.world, chunk_edge, keep, path.string());
    part.palette = whole.world.palette;
    return WorldSlab{std::move(part), partition, world_format_name(format), false};
  });
}

}  // namespace voxfield::mpi
