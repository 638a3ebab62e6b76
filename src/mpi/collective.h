// voxfield — what the MPI layer's collective operations share (internal): timing of the calls
// that talk to the other ranks, and MPI's error texts. The agreement on failures (agree,
// collectively) is public, in mpi.h.
#pragma once

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "voxfield/mpi.h"

namespace voxfield::mpi::detail {

// Milliseconds since `t0`.
inline double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// Adds one collective call's time to the stats.
class CollectiveTimer {
 public:
  explicit CollectiveTimer(ExchangeStats* stats) : stats_(stats) {}
  ~CollectiveTimer() {
    if (stats_) {
      stats_->exchange_ms += ms_since(t0_);
      ++stats_->collectives;
    }
  }
  CollectiveTimer(const CollectiveTimer&) = delete;
  CollectiveTimer& operator=(const CollectiveTimer&) = delete;

 private:
  ExchangeStats* stats_;
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

// mpi::collectively and mpi::agree with the layer's counters before the lambda (the order every
// caller in the layer reads best in).
template <class Fn>
auto collectively(MPI_Comm comm, ExchangeStats* stats, Fn&& fn) {
  return mpi::collectively(comm, std::forward<Fn>(fn), stats);
}
inline void agree(MPI_Comm comm, const std::string& error, ExchangeStats* stats) {
  mpi::agree(comm, error, stats);
}

// The partition is one slab per rank of `comm` (InvalidArgument otherwise).
void require_partition(MPI_Comm comm, const SlabPartition& partition);

// Rank 0's `text` on every rank.
std::string broadcast_string(MPI_Comm comm, std::string text, ExchangeStats* stats);

// The largest message the layer sends in one call: MPI counts are ints, and pieces of this size
// keep a transfer's buffers in MPI's eager and rendezvous paths alike.
constexpr std::size_t kMessageBytes = std::size_t{256} << 20;

// Rank 0's `bytes` on every rank (byte_transfer.cpp): the size first, each rank's room for it
// agreed on (ResourceLimitError past a rank's memory limit, naming `name`, on every rank), then
// the bytes.
std::vector<std::uint8_t> broadcast_bytes(MPI_Comm comm, std::vector<std::uint8_t> bytes,
                                          const std::string& name, ExchangeStats* stats);
// Rank 0's `bytes` on rank `to` alone, the same way (every rank calls it; the others pass nothing
// and get nothing; `to` 0 keeps rank 0's own).
std::vector<std::uint8_t> send_bytes(MPI_Comm comm, int to, std::vector<std::uint8_t> bytes,
                                     const std::string& name, ExchangeStats* stats);
// Rank `from`'s `bytes` on rank `to` alone, the same way (send_bytes is from 0).
std::vector<std::uint8_t> move_bytes(MPI_Comm comm, int from, int to,
                                     std::vector<std::uint8_t> bytes, const std::string& name,
                                     ExchangeStats* stats);

// Bytes of a shared file at an offset.
struct FilePiece {
  std::uint64_t offset = 0;
  std::vector<std::uint8_t> bytes;
};

// Every rank opens `temporary` (staged by rank 0) by itself, writes its pieces and closes it — no
// collective call, so a rank that fails leaves none waiting; returns this rank's error (empty on
// success) for the caller to agree on. `target` names the file in messages.
std::string write_pieces(MPI_Comm comm, const std::string& temporary, const std::string& target,
                         const std::vector<FilePiece>& pieces);

// The union of every rank's box (empty boxes add nothing): one all-reduce of six integers.
Box3i unite_over_ranks(MPI_Comm comm, const Box3i& mine, ExchangeStats* stats);

// An exclusive scan of `mine` over the ranks in rank order (0 on rank 0), and the total.
std::pair<std::uint64_t, std::uint64_t> exclusive_scan(MPI_Comm comm, std::uint64_t mine,
                                                       ExchangeStats* stats);

// A duplicate of a communicator, freed on leaving scope: an operation's point-to-point messages
// travel on it, so that none of the application's messages on the original can match theirs.
struct OwnComm {
  MPI_Comm comm = MPI_COMM_NULL;
  explicit OwnComm(MPI_Comm from) { MPI_Comm_dup(from, &comm); }
  ~OwnComm() { MPI_Comm_free(&comm); }
  OwnComm(const OwnComm&) = delete;
  OwnComm& operator=(const OwnComm&) = delete;
};

// The layers are dealt to `ranks` ranks, cut for the frame's lattice and the options' chunk edge,
// and cover every layer once in rank order (InvalidArgument naming `who` otherwise).
void check_mesh_layers(const MeshLayers& layers, const ScalarVolume& frame,
                       const MeshOptions& options, int ranks, const char* who);

// The text of an MPI error code.
std::string mpi_error_text(int code);

}  // namespace voxfield::mpi::detail
