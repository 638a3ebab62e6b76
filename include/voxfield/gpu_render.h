// voxfield — the render module's GPU half: the ray marcher as a Vulkan compute shader, for one
// frame (gpu::render) or for a scene kept resident across frames (gpu::SceneRenderer). The CPU half
// is render.h. An application's own device and command buffer: gpu_render_vulkan.h.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include "voxfield/csg_render.h"
#include "voxfield/gpu.h"
#include "voxfield/render.h"

namespace voxfield::gpu {

// Renders a frame of `scene` with the ray-marching compute shader: the CPU renderer's traversal,
// data and shading, in floats — images match the CPU's within the tolerance tests/test_gpu.cpp
// states. Every view (the error view's counts, rays_through_geometry and max_error, stay zero:
// the CPU renderer reports them). One submit; stats->ms covers upload, render and read-back.
// The error view first computes its approximation on the device (gpu_distance.h; brute force on
// the CPU): one more submit and fence wait, outside stats->ms. For many frames of a changing
// scene, use SceneRenderer, which keeps the approximation until the scene or the algorithm
// changes.
Image render(Context& context, const RenderScene& scene, const Camera& camera,
             const RenderOptions& options, RenderStats* stats = nullptr,
             std::vector<PassTiming>* timings = nullptr);

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

// A DynamicRenderScene that lives on the device: the skip and lighting fields are computed there
// (gpu::DynamicField: exact, the CPU's values bit for bit) and the ray marcher's cells are packed
// from them there, so the fields are drawn where they were computed, without a trip through the
// host. After edits of the world, update() uploads the chunks that changed, updates both fields
// incrementally and re-packs the chunks they reached, the chunks DynamicRenderScene re-reads.
// What comes back to the host: 8 bytes per packed chunk (its smallest and largest stored distance
// and lighting value, and whether it holds a solid voxel), from which the host decides which
// chunks are stored voxel by voxel, as RenderScene decides. Frames are SceneRenderer's frames of
// a DynamicRenderScene of the same world and options, pixel for pixel. Not thread-safe; one frame
// at a time.
class DeviceRenderScene {
 public:
  // Binds to `world` (it must outlive the scene) and builds both fields and the cells over `box`
  // (default: the world's bounds; InvalidArgument for an unbounded world without one, and for an
  // empty box). Throws InvalidArgument as DynamicRenderScene and gpu::DynamicField do (unit
  // spacing, u8 fields within the device's storage-buffer range), GpuUnavailable on device errors.
  DeviceRenderScene(std::shared_ptr<Context> context, const World& world,
                    RenderSceneOptions options = DynamicRenderScene::default_options(),
                    std::optional<Box3i> box = std::nullopt);
  ~DeviceRenderScene();
  DeviceRenderScene(const DeviceRenderScene&) = delete;
  DeviceRenderScene& operator=(const DeviceRenderScene&) = delete;

  // Hardware-independent counters of a build or an update, and its times (on lavapipe, CPU
  // emulation).
  struct UpdateStats {
    double field_ms = 0;  // both fields on the device, submits and fence waits included
    double scene_ms = 0;  // summarising and packing the chunks they reached
    std::int64_t voxels_recomputed = 0;
    std::size_t chunks_repacked = 0;
    std::size_t bytes_up = 0;    // host to device: changed world chunks, chunk lists, entries
    std::size_t bytes_down = 0;  // device to host: the packed chunks' summaries
    int submits = 0;             // each with one fence wait
  };
  // Brings the fields and the cells up to date after the edits recorded in `dirty` (tracking
  // every material change, DirtyRegions::Track::kAnyChange). The caller clears `dirty` afterwards.
  // The fields keep DynamicField's guarantees; after a throw, build the scene again.
  UpdateStats update(const DirtyRegions& dirty);
  const UpdateStats& build_stats() const;

  // A frame, read back (as SceneRenderer::render).
  Image render(const Camera& camera, const RenderOptions& options, RenderStats* stats = nullptr,
               std::vector<PassTiming>* timings = nullptr);
  const Box3i& box() const;
  Context& context();

  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// ---- CSG models ---------------------------------------------------------------------------------

struct CsgGpuOptions {
  // Which kernel marches a variant's cells: its own generated shader, compiled before the frame
  // (kCompiled); the interpreter running its program (kInterpreter); or the interpreter until the
  // variant's shader, compiled on worker threads meanwhile, is ready (kCompiledWhenReady —
  // Palecek's placeholder scheme). All three give the same image.
  enum class Evaluators { kCompiledWhenReady, kCompiled, kInterpreter };
  Evaluators evaluators = Evaluators::kCompiledWhenReady;
};

// Hardware-independent figures of one CSG frame.
struct CsgGpuStats {
  int rounds = 0;  // advance / bin / scatter / march rounds, primary and shadow rays
  int variants = 0, variants_compiled = 0;  // compiled: shaders ready by the frame's end
  std::int64_t compiled_dispatches = 0, interpreted_dispatches = 0;  // variant marches
  std::int64_t dispatches = 0, submits = 0;
  double compile_ms = 0;  // kCompiled: compiling the variants before the frame
};

// render_csg (csg_render.h) on Vulkan: the same octree, camera, epsilon and shading, sphere traced
// in floats by one generated kernel per variant (or the interpreter); images match the CPU's within
// the tolerance tests/test_gpu_render.cpp states. stats gets the octree and frame times and the
// variant count (the per-evaluation counters are the CPU's). Throws InvalidArgument for an octree
// deeper than 8 or larger than a storage buffer, for kInterpreter with a variant beyond the
// interpreter's registers, and as render_csg does.
Image render_csg(Context& context, const csg::Model& model, const CsgRenderOptions& options,
                 CsgRenderStats* stats = nullptr, const CsgGpuOptions& gpu_options = {},
                 CsgGpuStats* gpu_stats = nullptr);

}  // namespace voxfield::gpu
