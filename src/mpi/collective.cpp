// voxfield — agreement between the ranks of a collective operation (collective.h).
#include "collective.h"

#include <algorithm>
#include <array>
#include <limits>

#include "voxfield/error.h"

namespace voxfield::mpi {

void agree(MPI_Comm comm, const std::string& error, ExchangeStats* stats) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // The lowest failing rank, or `size` when none failed.
  const int mine = error.empty() ? size : rank;
  int first = size;
  {
    detail::CollectiveTimer t(stats);
    MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  }
  if (first == size) return;
  // Its message, to every rank. An empty what() still says something.
  std::string text = rank == first ? (error.empty() ? std::string("failed") : error) : "";
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  throw RankError(first, text);
}

namespace detail {

void require_partition(MPI_Comm comm, const SlabPartition& partition) {
  int size = 0;
  MPI_Comm_size(comm, &size);
  if (partition.ranks() != size)
    throw InvalidArgument("a partition into " + std::to_string(partition.ranks()) +
                          " slabs for a communicator of " + std::to_string(size) + " ranks");
}

std::string broadcast_string(MPI_Comm comm, std::string text, ExchangeStats* stats) {
  CollectiveTimer t(stats);
  int length = static_cast<int>(text.size());
  MPI_Bcast(&length, 1, MPI_INT, 0, comm);
  text.resize(static_cast<std::size_t>(length));
  MPI_Bcast(text.data(), length, MPI_CHAR, 0, comm);
  return text;
}

namespace {

// Writes `bytes` at `offset` of the open file, in pieces MPI's int counts can take.
void write_at(MPI_File fh, std::uint64_t offset, const std::uint8_t* bytes, std::uint64_t n,
              const std::string& name) {
  constexpr std::uint64_t kPiece = std::uint64_t{1} << 30;
  for (std::uint64_t at = 0; at < n; at += kPiece) {
    const int count = static_cast<int>(std::min(kPiece, n - at));
    MPI_Status status;
    const int rc = MPI_File_write_at(fh, static_cast<MPI_Offset>(offset + at), bytes + at, count,
                                     MPI_BYTE, &status);
    if (rc != MPI_SUCCESS)
      throw IoError(name + ": write of " + std::to_string(count) + " bytes at offset " +
                    std::to_string(offset + at) + " failed: " + mpi_error_text(rc));
  }
}

}  // namespace

std::string write_pieces(MPI_Comm comm, const std::string& temporary, const std::string& target,
                         const std::vector<FilePiece>& pieces) {
  // Each rank opens the file on its own (MPI_COMM_SELF): the writes are independent, and a rank
  // that cannot open it (a path another node cannot see) must not leave the others in a
  // collective open or close; its error reaches them through the caller's agreement.
  (void)comm;
  MPI_File fh = MPI_FILE_NULL;
  std::string mpi_path = temporary;
  const int rc = MPI_File_open(MPI_COMM_SELF, mpi_path.data(), MPI_MODE_WRONLY, MPI_INFO_NULL, &fh);
  if (rc != MPI_SUCCESS) return target + ": cannot open " + temporary + ": " + mpi_error_text(rc);
  std::string error;
  try {
    for (const FilePiece& p : pieces)
      write_at(fh, p.offset, p.bytes.data(), p.bytes.size(), target);
  } catch (const std::exception& e) {
    error = e.what();
  }
  const int close_rc = MPI_File_close(&fh);
  if (close_rc != MPI_SUCCESS && error.empty())
    error = target + ": close failed: " + mpi_error_text(close_rc);
  return error;
}

std::string mpi_error_text(int code) {
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  if (MPI_Error_string(code, text, &length) != MPI_SUCCESS)
    return "MPI error " + std::to_string(code);
  return std::string(text, static_cast<std::size_t>(length));
}

Box3i unite_over_ranks(MPI_Comm comm, const Box3i& mine, ExchangeStats* stats) {
  constexpr std::int32_t kMax = std::numeric_limits<std::int32_t>::max();
  // Minima of the begins and of the negated ends, in one reduction; an empty box offers none.
  std::array<std::int32_t, 6> v{kMax, kMax, kMax, kMax, kMax, kMax};
  if (!mine.empty())
    for (int k = 0; k < 3; ++k) {
      v[static_cast<std::size_t>(k)] = mine.begin[k];
      v[static_cast<std::size_t>(k) + 3] = -mine.end[k];
    }
  std::array<std::int32_t, 6> all{};
  {
    CollectiveTimer t(stats);
    MPI_Allreduce(v.data(), all.data(), 6, MPI_INT32_T, MPI_MIN, comm);
  }
  if (all[0] == kMax) return {};
  return {{all[0], all[1], all[2]}, {-all[3], -all[4], -all[5]}};
}

std::pair<std::uint64_t, std::uint64_t> exclusive_scan(MPI_Comm comm, std::uint64_t mine,
                                                       ExchangeStats* stats) {
  CollectiveTimer t(stats);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::uint64_t before = 0, total = 0;
  MPI_Exscan(&mine, &before, 1, MPI_UINT64_T, MPI_SUM, comm);
  if (rank == 0) before = 0;  // MPI leaves rank 0's result undefined
  MPI_Allreduce(&mine, &total, 1, MPI_UINT64_T, MPI_SUM, comm);
  return {before, total};
}

}  // namespace detail

Box3i content_bounds(MPI_Comm comm, const SlabPartition& partition, const World& world) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const Box3i mine = collectively(comm, [&] {
    detail::require_partition(comm, partition);
    return world.voxels.content_bounds().intersect(partition.slab(rank));
  });
  return detail::unite_over_ranks(comm, mine, nullptr);
}

}  // namespace voxfield::mpi
