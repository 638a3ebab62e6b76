// voxfield-demo — the world being painted and what rendering it needs.
//
// Edits go through voxfield's incremental path: apply_edit records the changed boxes, and
// DynamicRenderScene brings both render fields and the scene up to date in time proportional to
// the edit (and, with the fields on a device, gpu::DeviceRenderScene does the same there). Only a
// change of metric, clamp, size or chunk edge rebuilds everything, and only when the user asks for
// it.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "voxfield/edit.h"
#include "voxfield/gpu_render.h"
#include "voxfield/render.h"

namespace voxfield::demo {

struct WorldSettings {
  int size = 128;  // terrain of size x size x size/2 voxels (ignored when loading)
  int chunk_edge = 16;
  Metric metric = Metric::kManhattan;  // the field rays skip by
  double max_distance_vox = 32;        // the clamp: how far a skip reaches, and an edit's reach
  std::uint64_t seed = 6683787;
};

class DemoWorld {
 public:
  // A generated terrain. Throws voxfield::Error for bad settings. No field is built yet: scene()
  // builds the host's, follow_on_device() the device's.
  explicit DemoWorld(const WorldSettings& settings);
  // A world read from a .vox, .npy or .vfw file, bounded to its extent with room above to build.
  DemoWorld(const WorldSettings& settings, const std::filesystem::path& file);

  // Applies edits (clipped to the world) in order, then updates fields and scene incrementally
  // once for all of them (overlapping edits are recomputed once).
  DynamicRenderScene::UpdateStats apply(std::span<const Edit> edits);
  DynamicRenderScene::UpdateStats apply(const Edit& edit) {
    return apply(std::span<const Edit>(&edit, 1));
  }
  // Rebuilds the fields for new metric / clamp settings (a full computation); bad settings throw
  // before anything changes. A device that cannot hold the new fields throws after the host's
  // scene is built with them, keeping no device copy (frames then come from the host's scene).
  void set_field(Metric metric, double max_distance_vox);
  // Keeps the fields on `context`'s device from now on (gpu::DeviceRenderScene): computed there,
  // updated there by every apply() and set_field(), drawn there — and only there: the host's
  // scene goes (the cursor picks voxels in the world itself), and comes back only if the device
  // fails or a CPU frame asks for it. Throws what DeviceRenderScene throws, keeping no device copy.
  void follow_on_device(std::shared_ptr<gpu::Context> context);
  gpu::DeviceRenderScene* device_scene() { return device_.get(); }
  // Drops the device's copy (before the device goes).
  void stop_device() {
    device_.reset();
    device_context_.reset();
  }

  // Writes the world (.vfw keeps the palette and bounds; .vox and .npy as the CLI writes them),
  // atomically.
  void save(const std::filesystem::path& path) const;

  const World& world() const { return *world_; }
  // The host's scene, for CPU frames: built here on first use (then kept up to date by apply()).
  const RenderScene& scene();
  // The box drawn and edited: the world's bounds (a RenderScene's default box).
  const Box3i& box() const { return box_; }
  // The voxel under a ray (the cursor's), read from the world: no scene needed.
  RayHit pick(const Ray& ray) const { return trace_ray(*world_, ray, box()); }
  const WorldSettings& settings() const { return settings_; }
  std::int64_t edits() const { return edits_; }
  const std::string& origin() const { return origin_; }

 private:
  void make_scene();

  WorldSettings settings_;
  std::unique_ptr<World> world_;  // fixed address: the scene refers to it
  Box3i box_;
  std::unique_ptr<DynamicRenderScene> live_;      // the host's scene, when it is kept
  std::shared_ptr<gpu::Context> device_context_;  // set by follow_on_device
  std::unique_ptr<gpu::DeviceRenderScene> device_;
  DirtyRegions dirty_;
  std::int64_t edits_ = 0;
  std::string origin_;  // "terrain 128x128x64" or the file name
};

}  // namespace voxfield::demo
