// voxfield-mpi: figures over the ranks of a job, for the commands' --stats JSON.
#pragma once

#include <mpi.h>
#include <sys/resource.h>

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <vector>

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

// Every rank's phases of a frame (mpi::RenderPhases), gathered on rank 0 (empty elsewhere): per
// phase the ms of each rank, and of those the ms waited in collective calls.
inline nlohmann::json phases_json(MPI_Comm comm, const mpi::RenderPhases& p) {
  const mpi::RenderPhase* each[] = {&p.skip, &p.scene, &p.first_hits, &p.shadows, &p.shade};
  const char* names[] = {"skip", "scene", "first_hits", "shadows", "shade"};
  constexpr int kValues = 2 * 5 + 1;
  std::vector<double> mine;
  for (const mpi::RenderPhase* phase : each) mine.insert(mine.end(), {phase->ms, phase->wait_ms});
  mine.push_back(p.relay_rounds);
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::vector<double> all(rank == 0 ? static_cast<std::size_t>(kValues) * size : 0);
  MPI_Gather(mine.data(), kValues, MPI_DOUBLE, all.data(), kValues, MPI_DOUBLE, 0, comm);
  nlohmann::json out = nlohmann::json::object();
  if (rank != 0) return out;
  for (int k = 0; k < 5; ++k) {
    nlohmann::json ms = nlohmann::json::array(), wait = nlohmann::json::array();
    for (int r = 0; r < size; ++r) {
      ms.push_back(all[static_cast<std::size_t>(r * kValues + 2 * k)]);
      wait.push_back(all[static_cast<std::size_t>(r * kValues + 2 * k + 1)]);
    }
    out[names[k]] = {{"ms", ms}, {"wait_ms", wait}};
  }
  out["relay_rounds"] = static_cast<int>(all[kValues - 1]);
  return out;
}

}  // namespace voxfield::mpi_cli
