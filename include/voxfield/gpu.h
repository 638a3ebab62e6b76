// voxfield — the GPU compute layer: a Vulkan device (gpu::Context) and choosing between it and
// the CPU. The modules' GPU halves sit beside their CPU halves: gpu_distance.h (exact fields, the
// algorithm family, the incremental field) and gpu_render.h (the ray marcher).
//
// Built when the Vulkan headers, volk and glslc are present (preset cpu-only builds without it);
// at run time the Vulkan loader is opened dynamically, so a machine without Vulkan still runs
// everything on the CPU. Nothing here includes Vulkan headers: applications that hand voxfield
// their own Vulkan device use gpu_vulkan.h.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "voxfield/error.h"

namespace voxfield {

// No usable GPU: no Vulkan loader, no device, a device without what voxfield needs, or a build
// without the Vulkan backend. The message says which. Callers that fall back to the CPU catch this
// class, which also covers the two failures below. Nothing the call was given has changed.
class GpuUnavailable : public Error {
 public:
  using Error::Error;
};

// The device was lost during the call (a driver reset, a hang, a removed GPU). Everything on the
// device is gone: the Context reports lost() from then on, every later call on it or on an object
// made with it throws GpuDeviceLost again, and those objects can only be destroyed — make a new
// Context (or fall back to the CPU). CPU-side objects (worlds, fields handed in) are unchanged.
class GpuDeviceLost : public GpuUnavailable {
 public:
  using GpuUnavailable::GpuUnavailable;
};

// The device (or the host memory the driver needs) ran out of memory. The call's own allocations
// are freed and the Context stays usable; an object that keeps data resident on the device
// (gpu::DynamicField, gpu::SceneRenderer) may hold a partly updated copy afterwards, so it must be
// rebuilt — DynamicField::rebuild(), SceneRenderer::sync() of a newly made scene — before its next
// use, or destroyed.
class GpuOutOfMemory : public GpuUnavailable {
 public:
  using GpuUnavailable::GpuUnavailable;
};

enum class Backend { kCpu, kVulkan, kAuto };
const char* backend_name(Backend b);             // "cpu", "vulkan", "auto"
Backend parse_backend(const std::string& name);  // throws InvalidArgument

namespace gpu {

// True when this build has the Vulkan backend.
bool built_with_vulkan();

struct ContextOptions {
  // Enable the Khronos validation layer with synchronisation validation, and collect its
  // messages (validation_messages()). Throws GpuUnavailable when the layer is not installed.
  bool validation = false;
  // Accept CPU implementations of Vulkan such as Mesa's lavapipe.
  bool allow_software = true;
  // At most this many bytes in one storage buffer binding (0: the device's
  // maxStorageBufferRange; a larger value is lowered to it; at least 4 KiB and the device's
  // minStorageBufferOffsetAlignment, InvalidArgument otherwise). Work that does not fit is done in
  // parts where it can be (a distance field's passes in slabs — with the clamp's halo, or with
  // each column's nearest sites beyond the slab — and large buffers bound in windows:
  // docs/gpu.md) and refused, naming the sizes, where it cannot; lower it to leave room
  // on a device shared with other programs. (An adopted device takes the same cap:
  // AdoptedDevice, gpu_vulkan.h.)
  std::uint64_t max_storage_buffer_bytes = 0;
  // Which device, among the usable ones (Vulkan 1.1, a compute queue, hardware unless
  // allow_software) of the most capable kind present (discrete GPUs, else integrated, else
  // virtual, else software): -1 the first the Vulkan loader lists; k >= 0 device k modulo their
  // number — so the processes of a job on one node, each passing its node-local rank, spread
  // over the node's GPUs (voxfield-mpi --device-per-rank) and none falls back to a software one.
  int device_index = -1;
};

struct DeviceInfo {
  std::string name;       // e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string type;       // "discrete", "integrated", "virtual", "cpu", "other"
  bool hardware = false;  // a real GPU (not "cpu")
  std::uint32_t api_version = 0;
  std::string api_version_string() const;
};

// Hardware-independent work counters: what a GPU frame or update costs in API traffic.
struct Counters {
  std::int64_t dispatches = 0;
  std::int64_t draws = 0;  // draw calls (the terrain renderer's indirect draws)
  std::int64_t pipeline_barriers = 0;
  std::int64_t submits = 0;
  std::int64_t fence_waits = 0;
  std::int64_t bytes_uploaded = 0;
  std::int64_t bytes_downloaded = 0;
  std::int64_t descriptor_pools = 0;  // descriptor pools created (sets are recycled, not pools)
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
  // True once the device was lost (see GpuDeviceLost): the context can only be destroyed.
  bool lost() const;

  struct Impl;
  Impl& impl() { return *impl_; }
  explicit Context(std::unique_ptr<Impl> impl);

 private:
  std::unique_ptr<Impl> impl_;
};

// Compiles a GLSL compute shader (#version 450, Vulkan rules) to SPIR-V in-process with glslang,
// e.g. the voxel compiler's generated variants. Thread-safe: shaders compile side by side on
// worker threads; needs no device. Throws InvalidArgument with glslang's log (naming `name` and the
// line) when the source does not compile, GpuUnavailable in a build without the Vulkan backend.
std::vector<std::uint32_t> compile_compute_shader(std::string_view name, std::string_view glsl);

// The backend to use: kCpu gives null; kVulkan a context on any Vulkan device, software included
// (throws GpuUnavailable if there is none); kAuto a context on a hardware GPU if there is one,
// otherwise null (the CPU). `why`, when given, receives one line saying what was chosen and why.
std::shared_ptr<Context> select_backend(Backend backend, const ContextOptions& options = {},
                                        std::string* why = nullptr);

}  // namespace gpu

// Where a module's work runs, chosen once and handed to its one API (distance_executor.h): the
// CPU (the default, and what an executor without a device is), or a Vulkan device shared by
// everything made with it.
class Executor {
 public:
  Executor() = default;  // the CPU
  explicit Executor(std::shared_ptr<gpu::Context> device) : device_(std::move(device)) {}
  // gpu::select_backend's choice: kCpu the CPU; kVulkan a device (GpuUnavailable if there is none);
  // kAuto a hardware GPU if there is one, otherwise the CPU. `why` receives one line.
  static Executor choose(Backend backend, const gpu::ContextOptions& options = {},
                         std::string* why = nullptr) {
    return Executor(gpu::select_backend(backend, options, why));
  }

  bool on_gpu() const { return device_ != nullptr; }
  Backend backend() const { return on_gpu() ? Backend::kVulkan : Backend::kCpu; }
  // The device (null on the CPU).
  gpu::Context* device() const { return device_.get(); }
  const std::shared_ptr<gpu::Context>& shared_device() const { return device_; }

 private:
  std::shared_ptr<gpu::Context> device_;
};
}  // namespace voxfield
