// voxfield — the distance module's GPU half: exact fields, the dissertation's algorithm family
// and the incremental field, computed with Vulkan compute on a gpu::Context. The CPU half is
// distance.h, algorithms.h and dynamic_field.h; results agree as each function states.
#pragma once

#include <memory>
#include <vector>

#include "voxfield/algorithms.h"
#include "voxfield/distance.h"
#include "voxfield/distance_slab.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/gpu.h"

namespace voxfield::gpu {

// The exact distance field computed on the GPU: the same values as voxfield::
// compute_distance_field — bit for bit for u8 and u16 storage; for f32, Euclidean values may
// differ from the CPU's by the GPU's square root (kF32Tolerance). Supported: every metric, signed
// or not, clamped or not, every storage, unit spacing, domains up to 16384 voxels per axis.
// Nearest sites too, the same site as the CPU's for every voxel (ties included).
// Throws InvalidArgument for what it does not support (anisotropic spacing, a
// fixed-point scale whose products overflow 32 bits), GpuUnavailable on device errors. One command
// buffer, one submit, one fence wait.
DistanceField compute_distance_field(Context& context, const World& world,
                                     const DistanceOptions& options,
                                     std::vector<PassTiming>* timings = nullptr);

// The slab [z0, z1) of the exact field of the whole domain options.domain (required), from the
// slab's own voxels of `world` and the nearest sites beyond it, `neighbours`: what
// voxfield::compute_slab_distance_field (distance_slab.h) gives, on the GPU, with the agreement
// stated above — so the slabs of a field split over the processes of an MPI job (mpi.h) can each
// be computed on a process's own device. The device holds the slab's world, field and work
// buffers alone. Throws
// InvalidArgument as the CPU's function does for a missing domain, a slab outside it or bad
// neighbours, and as compute_distance_field(Context&...) does for the rest.
DistanceField compute_slab_distance_field(Context& context, const World& world,
                                          const DistanceOptions& options, std::int32_t z0,
                                          std::int32_t z1, const SlabNeighbours& neighbours,
                                          std::vector<PassTiming>* timings = nullptr);

// One of the dissertation's algorithms on the GPU: kExact (as above); jump flooding — kJfaSeed,
// kJfa, kJfa1, kJfa2 — bit-identical to the CPU's (same passes, same tie rule, one command buffer
// per sign); kFim as Jacobi passes that stop themselves (indirect dispatch, one submit; L1 and
// L-inf bit-identical, Euclidean within 1e-4 voxels of the CPU's), kHybrid and kLod as JFA then
// FIM (two submits). kBrute and kBruteChunked (CPU references) throw InvalidArgument, as do FIM,
// hybrid and lod with nearest sites; unit spacing only.
DistanceField compute_distance_field(Context& context, const World& world,
                                     const DistanceOptions& options,
                                     const AlgorithmOptions& algorithm,
                                     AlgorithmStats* stats = nullptr,
                                     std::vector<PassTiming>* timings = nullptr);

class FieldEngine;
class Buffer;  // a device buffer of the compute layer (src/gpu/vulkan_context.h)

// Where a DynamicField's data lies on the device, for the GPU halves of voxfield's other modules
// (the render module's DeviceRenderScene packs its cells from them in place): the layout header
// (shaders/layout.h: Header), the world's page table and brick pool, and the stored values, rows
// of Header::field_size.w values padded to whole words. Valid until the next update() or
// rebuild(), which may move the brick pool to a larger buffer.
struct ResidentField {
  Buffer* header = nullptr;
  Buffer* pages = nullptr;
  Buffer* bricks = nullptr;
  Buffer* values = nullptr;
  Box3i domain;
  DistanceEncoding encoding;
  std::uint32_t background_bits = 0;  // the stored value of voxels outside the domain
};

// A distance field that lives on the GPU and follows its world through edits, like
// DynamicDistanceField: update() uploads the chunks that changed (only those, through a reusable
// staging buffer, into the resident brick pool and page table) and recomputes the same regions the
// CPU would, exactly — one command buffer, one submit, one fence wait, no read-back.
class DynamicField {
 public:
  // Binds to `world` (which must outlive this object; the domain must stay fixed: a bounded world
  // or options.domain) and builds the field on the GPU. Throws InvalidArgument as
  // compute_distance_field(Context&...) does, GpuUnavailable on device errors.
  DynamicField(std::shared_ptr<Context> context, const World& world, DistanceOptions options);
  // Another field of `owner`'s world on owner's resident world — its page table and brick pool,
  // so the device holds one copy of the world however many fields derive from it — and on its
  // work buffers (both fields' passes run one submission at a time). The domain (default:
  // owner's) must touch the same chunks as owner's, and owner must own its world, not ride on
  // another's (InvalidArgument otherwise). update() of this field uploads nothing: call
  // owner.update() with the same edits first.
  DynamicField(DynamicField& owner, DistanceOptions options);
  ~DynamicField();
  DynamicField(const DynamicField&) = delete;
  DynamicField& operator=(const DynamicField&) = delete;

  // If rebuild() or update() throws (a device error, a region refused), the field is not exact
  // for its world until a rebuild() succeeds; the next run sends the whole world again, since
  // the device's copy of it is in doubt.
  void rebuild();
  DynamicDistanceField::UpdateStats update(const DirtyRegions& dirty);
  // Reads the resident field back (for saving, checking or CPU consumers).
  DistanceField download();

  const DistanceOptions& options() const;
  // Bytes of the resident field: 1, 2 or 4 per voxel of the domain (u8, u16, f32), as on the CPU,
  // rows padded to whole 32-bit words.
  std::size_t field_bytes() const;
  Vec3i reach() const { return reach_; }
  Context& context() { return *context_; }
  // Timestamps of the last build or update's passes (empty without timestamp support).
  const std::vector<PassTiming>& last_timings() const { return timings_; }
  // Bytes the last build or update copied to the device (header, page entries, bricks).
  std::size_t last_upload_bytes() const;
  ResidentField resident();

 private:
  std::shared_ptr<Context> context_;
  std::unique_ptr<FieldEngine> engine_;
  VoxelFrame frame_;  // the world's when bound: download()'s fields carry it
  Vec3i reach_{0, 0, 0};
  int chunk_shift_ = 0;
  std::vector<PassTiming> timings_;
};

// Largest |GPU - CPU| of f32 Euclidean values, relative to the distance: Vulkan allows sqrt an
// error of a few ulps (the SPIR-V environment spec inherits it from 1/inversesqrt).
constexpr double kF32Tolerance = 4e-7;

}  // namespace voxfield::gpu
