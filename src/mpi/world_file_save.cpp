// voxfield — one .vfw world file written by every rank, each the chunks of its slab (mpi.h):
// byte for byte the file one process writes for the whole world.
//
// A .vfw's world section is a header, then one record per chunk in (z, y, x) order, then a CRC-32
// of the section (docs/formats.md). A rank whose slab is cut on chunk boundaries owns whole chunk
// layers, so the ranks' records follow each other in rank order: an exclusive scan of their sizes
// gives each its offset, rank 0 writes the header (with the total chunk count) and the CRC, joined
// from the ranks' own CRCs (zlib's crc32_combine), and renames the file once all have written.
#include <array>
#include <optional>

#include "collective.h"
#include "voxfield/file.h"
#include "voxfield/world_file.h"

namespace voxfield::mpi {
namespace {

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

}  // namespace

void save_world_vfw(MPI_Comm comm, const SlabPartition& partition, const World& world,
                    const std::filesystem::path& path, ExchangeStats* stats,
                    FileTransaction* into) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int edge = world.voxels.chunk_edge();
  // This rank's chunk layers and their records.
  const WorldFilePart part = detail::collectively(comm, stats, [&] {
    detail::require_partition(comm, partition);
    for (int r = 1; r < size; ++r) {
      if (partition.z[static_cast<std::size_t>(r)] % edge != 0)
        throw InvalidArgument(path.string() +
                              ": a .vfw written by several ranks needs slabs cut on "
                              "chunk boundaries; the cut at z " +
                              std::to_string(partition.z[static_cast<std::size_t>(r)]) +
                              " is not a multiple of the chunk edge " + std::to_string(edge) +
                              " (fewer ranks or a smaller chunk edge)");
    }
    const Box3i slab = partition.slab(rank);
    const auto first = static_cast<std::int32_t>(floor_div(slab.begin.z, edge));
    const auto last = static_cast<std::int32_t>(floor_div(slab.end.z - 1, edge) + 1);
    return encode_world_file_part(world.voxels, first, last);
  });
  // Every rank's summary to rank 0, and every rank's offset among the records.
  const std::array<std::uint64_t, 3> mine{part.chunks, part.records.size(), part.crc};
  std::vector<std::uint64_t> all(rank == 0 ? 3 * static_cast<std::size_t>(size) : 0);
  std::uint64_t offset = 0;
  {
    detail::CollectiveTimer t(stats);
    MPI_Gather(mine.data(), 3, MPI_UINT64_T, all.data(), 3, MPI_UINT64_T, 0, comm);
    std::uint64_t bytes = part.records.size();
    MPI_Exscan(&bytes, &offset, 1, MPI_UINT64_T, MPI_SUM, comm);
    if (rank == 0) offset = 0;  // MPI leaves rank 0's result undefined
  }
  // Rank 0 stages the file with its header and learns where the tail goes.
  std::optional<FileTransaction> own;
  FileTransaction* transaction = into;
  std::vector<std::uint8_t> tail;
  std::string staged;  // temporary '\0' header bytes '\n' record bytes
  detail::collectively(comm, stats, [&] {
    if (rank != 0) return;
    std::vector<WorldFilePartSummary> parts;
    std::uint64_t records = 0;
    for (int r = 0; r < size; ++r) {
      const std::size_t i = 3 * static_cast<std::size_t>(r);
      parts.push_back({all[i], all[i + 1], static_cast<std::uint32_t>(all[i + 2])});
      records += all[i + 1];
    }
    const WorldFileFrame frame =
        encode_world_file_frame(world.palette, edge, partition.domain, parts, world.frame);
    if (!transaction) transaction = &own.emplace();
    // '\0' after the name: the one byte no path holds.
    staged = transaction->stage_shared(path, frame.head).string() + std::string(1, '\0') +
             std::to_string(frame.head.size()) + "\n" + std::to_string(records);
    tail = frame.tail;
  });
  staged = detail::broadcast_string(comm, staged, stats);
  const std::size_t a = staged.find('\0'), b = staged.find('\n', a + 1);
  const std::string temporary = staged.substr(0, a);
  const std::uint64_t head_bytes = std::stoull(staged.substr(a + 1, b - a - 1));
  const std::uint64_t record_bytes = std::stoull(staged.substr(b + 1));
  std::vector<detail::FilePiece> pieces;
  pieces.push_back({head_bytes + offset, part.records});
  if (rank == 0) pieces.push_back({head_bytes + record_bytes, tail});
  const std::string error = detail::write_pieces(comm, temporary, path.string(), pieces);
  if (stats && rank != 0) stats->bytes_sent += 24;  // the summary; the records go to the file
  detail::agree(comm, error, stats);
  detail::collectively(comm, stats, [&] {
    if (rank == 0 && own) own->commit();
  });
}

}  // namespace voxfield::mpi
