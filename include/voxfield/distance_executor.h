// voxfield — the distance module's one API over both backends: exact fields, the dissertation's
// algorithm family and the incremental field, run where an Executor says (gpu.h): the CPU
// (distance.h, algorithms.h, dynamic_field.h) or a Vulkan device (gpu_distance.h). Results agree as
// those headers state — bit for bit except f32 Euclidean square roots (gpu::kF32Tolerance) and
// FIM's Euclidean passes. Write one code path; choose the backend once.
#pragma once

#include <memory>
#include <optional>

#include "voxfield/algorithms.h"
#include "voxfield/distance.h"
#include "voxfield/distance_slab.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/gpu.h"
#include "voxfield/gpu_distance.h"

namespace voxfield {

// The exact field (or, with `algorithm`, one of the family's) of `world` on `executor`. Throws what
// the chosen backend's function throws: InvalidArgument for options it does not support (the GPU
// supports fewer: see gpu_distance.h), GpuUnavailable and its kinds on device errors.
DistanceField compute_distance_field(const Executor& executor, const World& world,
                                     const DistanceOptions& options,
                                     const AlgorithmOptions& algorithm = {},
                                     AlgorithmStats* stats = nullptr);

// The slab [z0, z1) of the exact field of the whole domain options.domain, from the slab's own
// voxels and the nearest sites beyond it (distance_slab.h), on `executor`: the slabs of a field
// split over an MPI job's processes (mpi.h), each on its own process's backend. Throws as
// compute_slab_distance_field (distance_slab.h) or its GPU half (gpu_distance.h) does.
DistanceField compute_slab_distance_field(const Executor& executor, const World& world,
                                          const DistanceOptions& options, std::int32_t z0,
                                          std::int32_t z1, const SlabNeighbours& neighbours);

// A distance field that follows its world through edits, on the CPU (DynamicDistanceField) or
// resident on a device (gpu::DynamicField) — one type for both, so an application, the CLI and the
// tests run the same code whichever backend was chosen.
class IncrementalDistanceField {
 public:
  // Binds to `world` (which must outlive this object; a fixed domain: a bounded world or
  // options.domain) and builds the field. Throws as the chosen backend's constructor does.
  IncrementalDistanceField(const Executor& executor, const World& world, DistanceOptions options);

  // Recomputes what the recorded changes can affect (the caller clears `dirty` afterwards); the
  // exception guarantees are the backend's (dynamic_field.h, gpu_distance.h).
  DynamicDistanceField::UpdateStats update(const DirtyRegions& dirty);
  // Recomputes the whole field.
  void rebuild();

  // The current field: the CPU's own, or the device's read back once per change (bytes moved).
  // The reference is valid until the next update() or rebuild() (on a device it names the copy
  // read back, which they drop); not thread-safe.
  const DistanceField& field();
  const DistanceOptions& options() const;
  Vec3i reach() const;
  // Bytes the field occupies where it lives — the CPU grid's chunks, or the device's resident
  // buffer — without reading a device's field back.
  std::size_t memory_bytes() const;
  const Executor& executor() const { return executor_; }
  bool on_gpu() const { return executor_.on_gpu(); }

 private:
  Executor executor_;
  std::optional<DynamicDistanceField> cpu_;
  std::unique_ptr<gpu::DynamicField> gpu_;
  std::optional<DistanceField> downloaded_;  // the device's field, read back since the last change
};

}  // namespace voxfield
