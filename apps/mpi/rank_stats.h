// voxfield-mpi: figures over the ranks of a job, for the commands' --stats JSON.
#pragma once

#include <mpi.h>
#include <sys/resource.h>

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>

#include "voxfield/mpi.h"

namespace voxfield::mpi_cli {

// Resident-set high-water mark of this process, in bytes.
inline std::size_t peak_rss_bytes() {
  struct rusage u {};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<std::size_t>(u.ru_maxrss) * 1024;  // Linux reports KiB
}

// The slowest rank's figure (times) and the sum over ranks (bytes).
inline double max_over(MPI_Comm comm, double v) {
  double out = 0;
  MPI_Allreduce(&v, &out, 1, MPI_DOUBLE, MPI_MAX, comm);
  return out;
}
inline std::uint64_t sum_over(MPI_Comm comm, std::uint64_t v) {
  std::uint64_t out = 0;
  MPI_Allreduce(&v, &out, 1, MPI_UINT64_T, MPI_SUM, comm);
  return out;
}

inline nlohmann::json exchange_json(MPI_Comm comm, const mpi::ExchangeStats& s) {
  return {{"compute_ms_max", max_over(comm, s.compute_ms)},
          {"exchange_ms_max", max_over(comm, s.exchange_ms)},
          {"bytes_sent_total", sum_over(comm, s.bytes_sent)},
          {"bytes_received_total", sum_over(comm, s.bytes_received)},
          {"collectives_per_rank", s.collectives}};
}

}  // namespace voxfield::mpi_cli
