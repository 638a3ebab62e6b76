// voxfield — a rank's slab of a world file (mpi.h): .npy arrays read a part per rank, bounded .vfw
// worlds decoded a slab per rank, other formats loaded whole by every rank.
#include <algorithm>

#include "collective.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/npy.h"
#include "voxfield/world_file.h"
#include "voxfield/world_io.h"

namespace voxfield::mpi {

WorldSlab load_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                          int ghost_slices) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  return detail::collectively(comm, nullptr, [&] {
    const WorldFormat format = world_format_of(path);
    // The slab and its ghost slices, once the domain is known.
    const auto kept_box = [&](const Box3i& domain, const SlabPartition& partition) {
      const Box3i slab = partition.slab(rank);
      const int ghost = std::max(ghost_slices, 0);
      return Box3i{{domain.begin.x, domain.begin.y,
                    static_cast<std::int32_t>(std::max<std::int64_t>(
                        domain.begin.z, std::int64_t{slab.begin.z} - ghost))},
                   {domain.end.x, domain.end.y,
                    static_cast<std::int32_t>(
                        std::min<std::int64_t>(domain.end.z, std::int64_t{slab.end.z} + ghost))}};
    };
    if (format == WorldFormat::kVfw) {
      // A bounded world's domain is in the file's head: each rank holds the compressed bytes and
      // decodes only its slab's chunks (every checksum and world chunk record still checked). An
      // unbounded world's domain is its content, known only once decoded: read whole, below.
      const std::uint64_t limit = effective_memory_limit(0);
      const std::vector<std::uint8_t> bytes = read_file(path, limit);
      WorldFileReadOptions head_only;
      head_only.memory_limit_bytes = remaining_memory(limit, bytes.size());
      head_only.keep_z = std::pair<std::int32_t, std::int32_t>{0, 0};
      const WorldFile head = parse_world_file(bytes, path.string(), head_only);
      if (const std::optional<Box3i> bounds = head.world.voxels.bounds()) {
        const SlabPartition partition = partition_slabs(*bounds, size, chunk_edge);
        const Box3i keep = kept_box(*bounds, partition);
        WorldFileReadOptions slab_only = head_only;
        slab_only.keep_z = std::pair<std::int32_t, std::int32_t>{keep.begin.z, keep.end.z};
        const WorldFile part = parse_world_file(bytes, path.string(), slab_only);
        World world = rechunk_world(part.world, chunk_edge, keep, path.string());
        return WorldSlab{std::move(world), partition, "vfw", true};
      }
    }
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
    const Box3i keep = kept_box(whole.extent, partition);
    World part = rechunk_world(whole.world, chunk_edge, keep, path.string());
    part.palette = whole.world.palette;
    return WorldSlab{std::move(part), partition, world_format_name(format), false};
  });
}

}  // namespace voxfield::mpi
