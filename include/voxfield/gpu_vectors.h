// voxfield — the vector-field module's GPU half: generations and steps of a vector-field volume
// texture as Vulkan compute passes, and the visualiser. The CPU half is vectors.h; this one gives
// the same textures.
//
// Every pass runs on the device: brute force (every voxel tests every source), splatting (every
// voxel tests the sources binned to its 8^3 tile — the CPU's per-source boxes turned into a gather,
// so no two invocations write one voxel), and jump flooding (a seeding pass, the passes of step
// N/2 ... 1 ping-ponged between two buffers, the exact conversion); a step's generation, decay and
// blend are one dispatch. Sources are uploaded per call into buffers the object reuses. The
// texture is a dense storage buffer laid out as VectorTexture::bytes() (x fastest; an rgba8 texel
// one word): a vector volume is dense by nature and small (64^3 to 256^3), so the sparse world grid
// would only add an indirection, and the layout is exactly what vkCmdCopyBufferToImage needs to
// fill a 3-D image for sampler3D sampling (voxfield_vectors.glsl).
//
// Exactness: distances, winners and directions are computed in doubles and encoded and blended
// in floats, operation for operation as the CPU does, with no fused multiply-adds. Where the
// device's division and square root are correctly rounded (lavapipe, and the double units of
// desktop GPUs) every texel equals the CPU's bit for bit in every storage —
// tests/test_gpu_vector_passes.cpp checks it on lavapipe. The visualiser works in floats and
// matches the CPU's image within the tolerance that test states. Needs the device feature
// shaderFloat64 (GpuUnavailable without it).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "voxfield/gpu.h"
#include "voxfield/image.h"
#include "voxfield/vectors.h"

namespace voxfield::gpu {

// Whether `context`'s device can run the vector-field passes (it needs shaderFloat64); `why`, when
// given, receives the reason when it cannot.
bool supports_vector_passes(Context& context, std::string* why = nullptr);

// Hardware-independent figures of one call, and its wall-clock time (on lavapipe, CPU emulation).
struct VectorGpuStats {
  std::int64_t dispatches = 0, submits = 0, fence_waits = 0;
  std::int64_t bytes_uploaded = 0, bytes_downloaded = 0;
  std::int64_t tile_entries = 0;  // splatting: (tile, source) pairs binned
  bool splat_as_brute = false;    // splatting's bins would have exceeded their memory: every
                                  // voxel tested every source instead (the same texels)
  int flood_passes = 0;
  double ms = 0;
};

// generate_vectors (vectors.h) on the device, the texture read back. `winners`, when given,
// receives each voxel's source as vector_winners returns it. Throws InvalidArgument as the CPU
// half does and for a texture larger than one storage buffer of the device; GpuUnavailable for a
// device without shaderFloat64.
VectorTexture generate_vectors(Context& context, const VectorVolume& volume,
                               std::span<const VectorSource> sources, VectorStorage storage,
                               const VectorOptions& options = {},
                               std::vector<std::int32_t>* winners = nullptr,
                               VectorGpuStats* stats = nullptr,
                               std::vector<PassTiming>* timings = nullptr);

// VectorSimulation (vectors.h) with its three textures resident on the device: each step() is
// one submission (uploads, the passes, no read-back) and one fence wait; field() reads the blended
// texture back, render() draws it where it is. Not thread-safe.
class VectorSimulation {
 public:
  // Throws as the CPU's constructor does, and as generate_vectors above.
  VectorSimulation(std::shared_ptr<Context> context, const VectorVolume& volume,
                   VectorStorage storage, VectorOptions options, double decay_per_s);
  ~VectorSimulation();
  VectorSimulation(const VectorSimulation&) = delete;
  VectorSimulation& operator=(const VectorSimulation&) = delete;

  // One step of dt seconds (> 0). If it throws InvalidArgument, nothing changed; after a GPU
  // failure the object must be destroyed (gpu.h).
  void step(std::span<const VectorSource> sources, double dt_s);
  VectorTexture field();    // the blended texture: what shaders sample (one read-back)
  VectorTexture current();  // the last step's generation (one read-back)
  Image render(const VectorViewOptions& view = {});  // the visualiser, on the resident field

  const VectorVolume& volume() const;
  VectorStorage storage() const;
  std::int64_t steps() const;
  const VectorGpuStats& last_stats() const;             // of the last step
  const std::vector<PassTiming>& last_timings() const;  // its passes, from timestamps
  Context& context();

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// render_vectors (vectors.h) on the device: one upload of the texture, one dispatch, one read-back.
Image render_vectors(Context& context, const VectorVolume& volume, const VectorTexture& texture,
                     const VectorViewOptions& view = {}, VectorGpuStats* stats = nullptr);

}  // namespace voxfield::gpu
