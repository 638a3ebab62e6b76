// voxfield — exact distance fields of volumes split over the processes of an MPI job.
//
// Each rank owns a slab of z-slices of the domain (SlabPartition) and holds only that slab of the
// world and of the field. The exact transform's first pass runs along z, so a slab needs from the
// others only each column's nearest solid and air voxel below and above it (distance_slab.h): two
// exclusive scans over the ranks of 16 bytes per column, whatever the clamp or metric, and the
// result equals compute_distance_field over the whole domain bit for bit.
//
// Every function here is collective over its communicator: all ranks call it with the same
// arguments (their own occupancy aside). A failure on any rank — a bad file, a memory limit, bad
// options — is agreed on before anything is written, and every rank then throws RankError naming
// the first failing rank and its message, so no rank waits forever on a collective the failed one
// never reaches. A rank that dies outright (a signal) is Open MPI's to report: mpirun ends the job.
//
// The communicator is the caller's (MPI_COMM_WORLD or a sub-communicator); MPI must be initialised
// (with at least MPI_THREAD_FUNNELED: only the calling thread talks to MPI, voxfield's thread pool
// works between the calls).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/world.h"

namespace voxfield::mpi {

// Rank r owns the slices [z[r], z[r + 1]) of the domain, the whole x-y extent.
struct SlabPartition {
  Box3i domain;
  std::vector<std::int32_t> z;  // ranks + 1 cut points, z.front() = domain.begin.z, z.back() = end

  int ranks() const { return static_cast<int>(z.size()) - 1; }
  Box3i slab(int rank) const;
};

// Slabs of near-equal volume: cuts at multiples of `align` slices from the domain's start (the
// chunk edge, so that no chunk is split between ranks) where every rank still gets at least one
// unit of `align`, else at single slices. Throws InvalidArgument when the domain has fewer slices
// than ranks (every rank must own one) or is empty.
SlabPartition partition_slabs(const Box3i& domain, int ranks, int align = 1);

// What a rank failed with, thrown on every rank of a collective operation that failed on any.
class RankError : public Error {
 public:
  RankError(int rank, const std::string& message)
      : Error("rank " + std::to_string(rank) + ": " + message), rank_(rank), message_(message) {}
  int rank() const { return rank_; }
  // The failing rank's message alone.
  const std::string& message() const { return message_; }

 private:
  int rank_;
  std::string message_;
};

// Counters of one rank's part of a collective computation.
struct ExchangeStats {
  std::uint64_t bytes_sent = 0;      // payload this rank contributed to the exchanges
  std::uint64_t bytes_received = 0;  // payload it received
  int collectives = 0;               // collective calls made (scans, reductions, broadcasts)
  double exchange_ms = 0;            // in those calls (waiting for slower ranks included)
  double compute_ms = 0;             // in this rank's own transform
};

// The exact field of the whole partition.domain, this rank's slab of it: `occupancy` (non-zero =
// solid) must hold this rank's slab (voxels outside it are not read); `options.domain` is ignored
// (the partition's domain is the field's). The returned field's domain is the slab; its values and
// nearest sites equal compute_distance_field's over the whole domain for those voxels.
DistanceField compute_distance_field(MPI_Comm comm, const SlabPartition& partition,
                                     const Grid<std::uint8_t>& occupancy,
                                     const DistanceOptions& options,
                                     ExchangeStats* stats = nullptr);

// A rank's slab of a world file.
struct WorldSlab {
  World world;  // the slab's voxels (at their place in the whole world)
  SlabPartition partition;
  std::string format;          // "npy", "vox" or "vfw"
  bool read_in_parts = false;  // each rank read only its slab (.npy); else each read the whole file
};

// Loads `path` for this rank: a .npy is read a part per rank (read_npy_part), so no rank holds more
// than its slab; a .vox or .vfw is loaded whole by every rank, which keeps its slab (those formats
// give no cheap way to read part of them; the memory of one whole world per rank is the cost). The
// domain is the file's volume (the .npy shape, the .vox/.vfw extent), as `voxfield field` uses.
WorldSlab load_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge);

// What write_field_npy writes.
struct FieldFiles {
  std::filesystem::path values;  // a[x, y, z] of the stored values (uint8, uint16 or float32)
  std::filesystem::path sites;   // optional: int16 a[x, y, z, 3] nearest-site offsets
  std::filesystem::path json;    // optional: written by rank 0 with `json_text`
  std::string json_text;
};

// Checks the targets as check_output_path does (on rank 0, whose file system view writes them),
// before any work: every rank throws RankError when one cannot be written.
void check_outputs(MPI_Comm comm, const FieldFiles& files);

// Writes every rank's slab of the field into one .npy per output, byte for byte what `voxfield
// field` writes for the whole domain, all or nothing: rank 0 stages temporaries beside the targets
// (FileTransaction::stage_shared), every rank writes its slices into them with MPI-IO, and only
// when all ranks succeeded does rank 0 rename them onto the targets. On failure no target is
// touched and the temporaries are removed.
void write_field_npy(MPI_Comm comm, const SlabPartition& partition, const DistanceField& slab,
                     const FieldFiles& files, ExchangeStats* stats = nullptr);

}  // namespace voxfield::mpi
