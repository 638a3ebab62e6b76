// voxfield — bytes moved between rank 0 and the others (collective.h): what load_world_slab's
// ReadBy::kRankZero sends to ranks that cannot see rank 0's files, and the parts of a .vdb the
// ranks send rank 0.
//
// Every transfer is agreed on before a byte moves: the size goes first, each receiving rank
// checks it against its memory limit and allocates, and the ranks agree on that, so a rank that
// cannot hold the bytes fails every rank with its reason instead of leaving rank 0 waiting in a
// send. The bytes then move in pieces of at most kMessageBytes (collective.h).
#include <algorithm>
#include <utility>

#include "collective.h"
#include "voxfield/limits.h"

namespace voxfield::mpi::detail {

namespace {

// Room for `n` bytes on this rank, agreed on by every rank (ResourceLimitError past the limit).
std::vector<std::uint8_t> agreed_room(MPI_Comm comm, bool receives, std::uint64_t n,
                                      const std::string& name, const std::string& what,
                                      ExchangeStats* stats) {
  return collectively(comm, stats, [&] {
    std::vector<std::uint8_t> room;
    if (receives) {
      require_memory(n, 0, name, what);
      room.resize(n);
    }
    return room;
  });
}

}  // namespace

std::vector<std::uint8_t> broadcast_bytes(MPI_Comm comm, std::vector<std::uint8_t> bytes,
                                          const std::string& name, ExchangeStats* stats) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  std::uint64_t n = bytes.size();
  {
    CollectiveTimer t(stats);
    MPI_Bcast(&n, 1, MPI_UINT64_T, 0, comm);
  }
  std::vector<std::uint8_t> room =
      agreed_room(comm, rank != 0, n, name, "the bytes rank 0 sends", stats);
  if (rank != 0) bytes = std::move(room);
  CollectiveTimer t(stats);
  for (std::uint64_t at = 0; at < n; at += kMessageBytes)
    MPI_Bcast(bytes.data() + at, static_cast<int>(std::min<std::uint64_t>(kMessageBytes, n - at)),
              MPI_BYTE, 0, comm);
  if (stats) (rank == 0 ? stats->bytes_sent : stats->bytes_received) += n;
  return bytes;
}

std::vector<std::uint8_t> move_bytes(MPI_Comm comm, int from, int to,
                                     std::vector<std::uint8_t> bytes, const std::string& name,
                                     ExchangeStats* stats) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (to == from) return rank == from ? bytes : std::vector<std::uint8_t>{};
  const OwnComm own(comm);  // the messages cannot match the application's on `comm`
  std::uint64_t n = bytes.size();
  if (rank == from) MPI_Send(&n, 1, MPI_UINT64_T, to, 0, own.comm);
  if (rank == to) MPI_Recv(&n, 1, MPI_UINT64_T, from, 0, own.comm, MPI_STATUS_IGNORE);
  std::vector<std::uint8_t> received = agreed_room(
      comm, rank == to, n, name, "the bytes rank " + std::to_string(from) + " sends", stats);
  CollectiveTimer t(stats);
  for (std::uint64_t at = 0; at < n; at += kMessageBytes) {
    const int count = static_cast<int>(std::min<std::uint64_t>(kMessageBytes, n - at));
    if (rank == from) MPI_Send(bytes.data() + at, count, MPI_BYTE, to, 1, own.comm);
    if (rank == to)
      MPI_Recv(received.data() + at, count, MPI_BYTE, from, 1, own.comm, MPI_STATUS_IGNORE);
  }
  if (stats && rank == from) stats->bytes_sent += n;
  if (stats && rank == to) stats->bytes_received += n;
  return received;
}

std::vector<std::uint8_t> send_bytes(MPI_Comm comm, int to, std::vector<std::uint8_t> bytes,
                                     const std::string& name, ExchangeStats* stats) {
  return move_bytes(comm, 0, to, std::move(bytes), name, stats);
}

}  // namespace voxfield::mpi::detail
