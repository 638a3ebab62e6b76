// voxfield GPU backend — what the vector-field passes keep on the device for one volume (the
// voxel-centre tables, the decode table, the per-call uploads, jump flooding's winners) and how a
// generation or a step is recorded. gpu_vectors.cpp builds the public entry points on it.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "gpu/recorder.h"
#include "voxfield/gpu_vectors.h"

namespace voxfield::gpu {

constexpr VkBufferUsageFlags kVectorBufferUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                                  VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT;

int vector_texel_bytes(VectorStorage storage);

class VectorEngine {
 public:
  // Throws GpuUnavailable without shaderFloat64, InvalidArgument for a texture larger than one
  // storage buffer of the device (volume.validate() first).
  VectorEngine(Context::Impl& c, const VectorVolume& volume, VectorStorage storage);

  // The textures of this volume and storage (zeroed when recorded by clear()).
  Buffer make_texture() const;
  std::uint64_t texture_bytes() const { return texture_bytes_; }

  // What one generation reads and writes. `previous` and `next` only for a step.
  struct Targets {
    Buffer* current = nullptr;
    Buffer* previous = nullptr;
    Buffer* next = nullptr;
    float decay = 0;            // a step: decay_per_s * dt, as a float
    bool want_winners = false;  // leave each voxel's source in winners()
  };
  // Records the uploads of `sources` and the passes of one generation (a step when targets has
  // previous and next) into `rec`, a recorder using sets(), once every command recorded by an
  // earlier record() or record_view() has finished (their uploads are reused). record_view() may
  // follow in the same command buffer: buffers it replaces are retired, not destroyed, until the
  // next record(). Throws InvalidArgument for invalid sources
  // (nothing recorded).
  void record(Recorder& rec, std::span<const VectorSource> sources, const VectorOptions& options,
              const Targets& targets, VectorGpuStats& stats);
  // The buffer holding the winners after a recorded generation with want_winners.
  Buffer& winners() { return *winners_; }
  // Records the visualiser over `texels` into the engine's pixel buffer (packed 8-bit pixels,
  // blue first with `bgra`); returns it.
  Buffer& record_view(Recorder& rec, Buffer& texels, const VectorViewOptions& view,
                      bool bgra = false);

  DescriptorArena& sets() { return sets_; }
  // Recycles the sets and destroys the retired buffers: only once every command recorded so far
  // has finished (record() does it itself).
  void settle();
  const VectorVolume& volume() const { return volume_; }
  VectorStorage storage() const { return storage_; }

 private:
  struct Upload;
  void stage(Recorder& rec, const Upload& up, VectorGpuStats& stats);
  Buffer& grow(Buffer& b, VkDeviceSize bytes, bool host_visible);

  Context::Impl& c_;
  VectorVolume volume_;
  VectorStorage storage_;
  std::uint64_t texture_bytes_ = 0;
  DescriptorArena sets_;
  Buffer centres_, decode_;            // once per volume
  Buffer segments_, tiles_, seeds_;    // per call, device-local
  Buffer staging_;                     // per call, host-visible: reused
  Buffer winners_a_, winners_b_;       // jump flooding's ping-pong (and winners wanted)
  Buffer* winners_ = nullptr;          // which of them holds the last generation's
  Buffer unused_read_, unused_write_;  // for bindings a pass leaves alone
  Buffer view_, pixels_;               // the visualiser's parameters and image
  std::vector<Buffer> retired_;        // replaced buffers earlier commands may still name
  bool uploaded_tables_ = false;
};

}  // namespace voxfield::gpu
