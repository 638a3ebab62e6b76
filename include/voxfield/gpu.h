// voxfield — the GPU backend (Vulkan compute), and choosing between it and the CPU.
//
// Built when the Vulkan headers, volk and glslc are present (preset cpu-only builds without it);
// at run time the Vulkan loader is opened dynamically, so a machine without Vulkan still runs
// everything on the CPU. Nothing here includes Vulkan headers: applications that hand voxfield
// their own Vulkan device use gpu_vulkan.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "voxfield/algorithms.h"
#include "voxfield/distance.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/render.h"
#include "voxfield/error.h"

namespace voxfield {

// No usable GPU: no Vulkan loader, no device, a device without what voxfield needs, or a build
// without the Vulkan backend. The message says which.
class GpuUnavailable : public Error {
 public:
  using Error::Error;
};

enum class Backend { kCpu, kVulkan, kAuto };
const char* backend_name(Backend b);              // "cpu", "vulkan", "auto"
Backend parse_backend(const std::string& name);   // throws InvalidArgument

namespace gpu {

// True when this build has the Vulkan backend.
bool built_with_vulkan();

struct ContextOptions {
  // Enable the Khronos validation layer with synchronisation validation, and collect its
  // messages (validation_messages()). Throws GpuUnavailable when the layer is not installed.
  bool validation = false;
  // Accept CPU implementations of Vulkan such as Mesa's lavapipe.
  bool allow_software = true;
};

struct DeviceInfo {
  std::string name;        // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string type;        // "discrete", "integrated", "virtual", "cpu", "other"
  bool hardware = false;   // a real GPU (not "cpu")
  std::uint32_t api_version = 0;
  std::string api_version_string() const;
};

// Hardware-independent work counters: what a GPU frame or update costs in API traffic.
struct Counters {
  std::int64_t dispatches = 0;
  std::int64_t pipeline_barriers = 0;
  std::int64_t submits = 0;
  std::int64_t fence_waits = 0;
  std::int64_t bytes_uploaded = 0;
  std::int64_t bytes_downloaded = 0;
};

// GPU time of one pass from timestamp queries (on lavapipe: CPU emulation, not GPU speed).
struct PassTiming {
  std::string pass;
  double ms = 0;
};

// A Vulkan instance, device and compute queue with voxfield's pipelines. Not thread-safe: one
// thread at a time.
class Context {
 public:
  // Creates its own instance and device (headless). Prefers a hardware GPU; accepts a software
  // one when options.allow_software. Throws GpuUnavailable.
  static std::shared_ptr<Context> create(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  const DeviceInfo& device() const;
  Counters counters() const;
  void reset_counters();
  // Messages of the validation layer since the last clear (warnings and errors).
  std::vector<std::string> validation_messages() const;
  void clear_validation_messages();
  bool has_timestamps() const;

  struct Impl;
  Impl& impl() { return *impl_; }
  explicit Context(std::unique_ptr<Impl> impl);

 private:
  std::unique_ptr<Impl> impl_;
};

// The backend to use: kCpu gives null; kVulkan a context on any Vulkan device, software included
// (throws GpuUnavailable if there is none); kAuto a context on a hardware GPU if there is one,
// otherwise null (the CPU). `why`, when given, receives one line saying what was chosen and why.
std::shared_ptr<Context> select_backend(Backend backend, const ContextOptions& options = {},
                                        std::string* why = nullptr);

// The exact distance field computed on the GPU: the same values as voxfield::
// compute_distance_field — bit for bit for u8 and u16 storage; for f32, Euclidean values may
// differ from the CPU's by the GPU's square root (kF32Tolerance). Supported: every metric, signed
// or not, clamped or not, every storage, unit spacing, domains up to 16384 voxels per axis.
// Nearest sites too, the same site as the CPU's for every voxel (ties included).
// Throws InvalidArgument for what it does not support (anisotropic spacing, a
// fixed-point scale whose products overflow 32 bits), GpuUnavailable on device errors. One command
// buffer, one submit, one fence wait.
DistanceField compute_distance_field(Context& context, const World& world, const DistanceOptions& options,
                                     std::vector<PassTiming>* timings = nullptr);

// One of the dissertation's algorithms on the GPU: kExact (as above); jump flooding — kJfaSeed,
// kJfa, kJfa1, kJfa2 — bit-identical to the CPU's (same passes, same tie rule, one command buffer
// per sign); kFim as Jacobi passes that stop themselves (indirect dispatch, one submit; L1 and
// L-inf bit-identical, Euclidean within 1e-4 voxels of the CPU's), kHybrid and kLod as JFA then
// FIM (two submits). kBrute and kBruteChunked (CPU references) throw InvalidArgument, as do FIM,
// hybrid and lod with nearest sites; unit spacing only.
DistanceField compute_distance_field(Context& context, const World& world, const DistanceOptions& options,
                                     const AlgorithmOptions& algorithm, AlgorithmStats* stats = nullptr,
                                     std::vector<PassTiming>* timings = nullptr);

class FieldEngine;

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
  ~DynamicField();
  DynamicField(const DynamicField&) = delete;
  DynamicField& operator=(const DynamicField&) = delete;

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

 private:
  std::shared_ptr<Context> context_;
  std::unique_ptr<FieldEngine> engine_;
  Vec3i reach_{0, 0, 0};
  int chunk_shift_ = 0;
  std::vector<PassTiming> timings_;
};

// Renders a frame of `scene` with the ray-marching compute shader: the CPU renderer's traversal,
// data and shading, in floats — images match the CPU's within the tolerance tests/test_gpu.cpp
// states. Every view (the error view's counts, rays_through_geometry and max_error, stay zero:
// the CPU renderer reports them). One submit; stats->ms
// covers upload, render and read-back. For many frames of a changing scene, use SceneRenderer.
Image render(Context& context, const RenderScene& scene, const Camera& camera, const RenderOptions& options,
             RenderStats* stats = nullptr, std::vector<PassTiming>* timings = nullptr);

// A RenderScene kept on the GPU for many frames — an editor's or a game's view of a changing
// world. The first sync() copies the whole scene; after RenderScene::update() only the chunks it
// re-read (and the palette) are copied, so an edit costs its chunks, not the world. Not
// thread-safe; one frame at a time (a frame's buffers are reused by the next).
class SceneRenderer {
 public:
  explicit SceneRenderer(std::shared_ptr<Context> context);  // InvalidArgument without a context
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Brings the GPU copy up to date with `scene` (another scene than last time is copied whole):
  // one submit and one fence wait when anything changed, none otherwise. Returns whether it copied.
  bool sync(const RenderScene& scene);
  // A frame of the synced scene, read back (as gpu::render; stats->ms covers render + read-back).
  // Throws InvalidArgument before the first sync and for what gpu::render refuses.
  Image render(const Camera& camera, const RenderOptions& options, RenderStats* stats = nullptr,
               std::vector<PassTiming>* timings = nullptr);
  Context& context();

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// Largest |GPU - CPU| of f32 Euclidean values, relative to the distance: Vulkan allows sqrt an
// error of a few ulps (the SPIR-V environment spec inherits it from 1/inversesqrt).
constexpr double kF32Tolerance = 4e-7;

}  // namespace gpu
}  // namespace voxfield
