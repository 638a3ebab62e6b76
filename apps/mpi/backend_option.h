// voxfield-mpi: --backend, where each rank computes its slab's field — the CPU or a Vulkan device
// of its own — and what the devices did, for --stats.
#pragma once

#include <mpi.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

#include "rank_stats.h"
#include "voxfield/gpu.h"

namespace voxfield::mpi_cli {

struct BackendSettings {
  std::string name = "cpu";      // --backend
  bool device_per_rank = false;  // --device-per-rank
};

inline void add_backend_option(CLI::App* cmd, BackendSettings& backend) {
  cmd->add_option("--backend", backend.name,
                  "cpu (default), vulkan or auto: where every rank computes its slab's field (each "
                  "rank opens a device of its own; auto takes a hardware GPU when every rank has "
                  "one)")
      ->check(CLI::IsMember({"cpu", "vulkan", "auto"}))
      ->capture_default_str();
  cmd->add_flag("--device-per-rank", backend.device_per_rank,
                "each rank on a node takes, among the node's most capable devices (its GPUs), "
                "the one of its node-local rank, modulo their number, instead of the first");
}

// Collective: every rank's executor, one backend for the whole job. A rank with no usable device
// for vulkan (or no hardware GPU for auto) puts every rank on the CPU — mixing backends would give
// f32 Euclidean slabs from two square roots — and rank 0 says so, as voxfield does on one machine.
inline Executor choose_rank_executor(MPI_Comm comm, const BackendSettings& backend) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  gpu::ContextOptions options;
  if (backend.device_per_rank) {
    // The rank among those sharing this node's memory (and so its devices).
    MPI_Comm node = MPI_COMM_NULL;
    MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
    MPI_Comm_rank(node, &options.device_index);
    MPI_Comm_free(&node);
  }
  const std::string& name = backend.name;
  std::string why;
  std::shared_ptr<gpu::Context> device;
  try {
    device = gpu::select_backend(parse_backend(name), options, &why);
  } catch (const std::exception& e) {  // GpuUnavailable, or a device that failed to open
    why = std::string("no usable Vulkan device (") + e.what() + ")";
  }
  const int mine = device ? 1 : 0;
  int with_device = 0;
  MPI_Allreduce(&mine, &with_device, 1, MPI_INT, MPI_SUM, comm);
  if (with_device < size) device.reset();
  if (rank == 0) {
    std::cerr << "voxfield-mpi: rank 0: " << why << "\n";
    if (with_device > 0 && with_device < size)
      std::cerr << "voxfield-mpi: " << size - with_device << " of " << size
                << " ranks have no device for --backend " << name
                << "; every rank uses the cpu backend\n";
  }
  return Executor(std::move(device));
}

// The devices' hardware-independent counters summed over the ranks (null on the CPU), and rank
// 0's device: every rank's dispatches, submits and bytes moved since its counters read `since`.
inline nlohmann::json gpu_json_over(MPI_Comm comm, const Executor& executor,
                                    const gpu::Counters& since = {}) {
  if (!executor.on_gpu()) return nullptr;
  gpu::Counters c = executor.device()->counters();
  c.dispatches -= since.dispatches;
  c.pipeline_barriers -= since.pipeline_barriers;
  c.submits -= since.submits;
  c.fence_waits -= since.fence_waits;
  c.bytes_uploaded -= since.bytes_uploaded;
  c.bytes_downloaded -= since.bytes_downloaded;
  const gpu::DeviceInfo& d = executor.device()->device();
  auto total = [&](std::int64_t v) {
    return static_cast<std::int64_t>(sum_over(comm, static_cast<std::uint64_t>(v)));
  };
  return {{"device_rank0", d.name},
          {"timings_are", d.hardware ? "gpu" : "cpu emulation"},
          {"dispatches_total", total(c.dispatches)},
          {"pipeline_barriers_total", total(c.pipeline_barriers)},
          {"submits_total", total(c.submits)},
          {"fence_waits_total", total(c.fence_waits)},
          {"bytes_uploaded_total", total(c.bytes_uploaded)},
          {"bytes_downloaded_total", total(c.bytes_downloaded)}};
}

}  // namespace voxfield::mpi_cli
