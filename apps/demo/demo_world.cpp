// voxfield-demo — the world being painted.
#include "demo_world.h"

#include <iostream>

#include "voxfield/error.h"
#include "voxfield/scene.h"
#include "voxfield/world_io.h"

namespace voxfield::demo {
namespace {

RenderSceneOptions scene_options(const WorldSettings& s) {
  RenderSceneOptions o = DynamicRenderScene::default_options();
  o.skip_metric = s.metric;
  o.skip_max_distance_vox = s.max_distance_vox;
  return o;
}

// The settings' refusals, before the world is made: no field is built here (the scene is, on the
// host or on a device, once the demo knows where its fields go).
void check_settings(const WorldSettings& s) {
  if (s.size < 16 || s.size > 1024)
    throw InvalidArgument("demo: --world must lie in 16..1024 voxels");
  if (s.chunk_edge < 8 || s.chunk_edge > 128 || (s.chunk_edge & (s.chunk_edge - 1)) != 0)
    throw InvalidArgument("demo: --chunk must be a power of two in 8..128");
  check_render_scene_options(scene_options(s));
}

}  // namespace

DemoWorld::DemoWorld(const WorldSettings& settings)
    : settings_(settings), dirty_(settings.chunk_edge, DirtyRegions::Track::kAnyChange) {
  check_settings(settings);
  SceneOptions so;
  so.size = {settings.size, settings.size, std::max(16, settings.size / 2)};
  so.seed = settings.seed;
  so.chunk_edge = settings.chunk_edge;
  world_ = std::make_unique<World>(make_terrain(so));
  origin_ = "terrain " + std::to_string(so.size.x) + "x" + std::to_string(so.size.y) + "x" +
            std::to_string(so.size.z);
  box_ = *world_->voxels.bounds();
}

DemoWorld::DemoWorld(const WorldSettings& settings, const std::filesystem::path& file)
    : settings_(settings), dirty_(settings.chunk_edge, DirtyRegions::Track::kAnyChange) {
  check_settings(settings);
  LoadOptions lo;
  lo.chunk_edge = settings.chunk_edge;
  LoadedWorld in = load_world(file, lo);
  Box3i extent = in.extent.unite(in.world.voxels.content_bounds());
  if (extent.empty()) throw InvalidArgument(file.string() + ": the world holds no voxels");
  // Room to build on top and around: a quarter of the largest side.
  const int margin = std::max({extent.size().x, extent.size().y, extent.size().z}) / 4;
  extent = Box3i{extent.begin - Vec3i{margin, margin, 0}, extent.end + Vec3i::splat(margin)};
  if (extent.volume() > std::int64_t{1024} * 1024 * 1024)
    throw InvalidArgument(file.string() + ": the world's box " + to_string(extent) +
                          " is too large for the demo");
  world_ =
      std::make_unique<World>(rechunk_world(in.world, settings.chunk_edge, extent, file.string()));
  origin_ = file.filename().string();
  box_ = *world_->voxels.bounds();
}

void DemoWorld::make_scene() {
  live_ = std::make_unique<DynamicRenderScene>(*world_, scene_options(settings_));
}

const RenderScene& DemoWorld::scene() {
  if (!live_) make_scene();
  return live_->scene();
}

void DemoWorld::follow_on_device(std::shared_ptr<gpu::Context> context) {
  device_.reset();
  device_context_.reset();
  device_ = std::make_unique<gpu::DeviceRenderScene>(context, *world_, scene_options(settings_));
  device_context_ = std::move(context);
  live_.reset();  // the device draws, and the cursor picks in the world
}

DynamicRenderScene::UpdateStats DemoWorld::apply(std::span<const Edit> edits) {
  dirty_.clear();
  for (const Edit& edit : edits) {
    apply_edit(*world_, edit, &dirty_);
    ++edits_;
  }
  DynamicRenderScene::UpdateStats st;
  if (device_) {
    try {
      const gpu::DeviceRenderScene::UpdateStats d = device_->update(dirty_);
      st.field_ms = d.field_ms;
      st.scene_ms = d.scene_ms;
      st.voxels_recomputed = d.voxels_recomputed;
      st.chunks_changed = d.chunks_repacked;
    } catch (const Error& e) {
      // Draw from the host from now on rather than stop: its scene, built from the edited world
      // (or brought up to date below, when a CPU frame kept one).
      std::cerr << "voxfield-demo: the fields stay on the host from now on: " << e.what() << "\n";
      stop_device();
      if (!live_) {
        make_scene();
        dirty_.clear();
        return st;
      }
    }
  }
  if (live_) st = live_->update(dirty_);
  dirty_.clear();
  return st;
}

void DemoWorld::set_field(Metric metric, double max_distance_vox) {
  WorldSettings next = settings_;
  next.metric = metric;
  next.max_distance_vox = max_distance_vox;
  // Bad options throw here, before anything changes (the device's copy included).
  check_render_scene_options(scene_options(next));
  // The host's scene is built first where it is kept (or no device is followed): a failure then
  // (the memory limit) leaves everything as it was.
  if (live_ || !device_context_) {
    auto live = std::make_unique<DynamicRenderScene>(*world_, scene_options(next));
    live_ = std::move(live);
  }
  if (device_context_) {
    // The old device copy goes first (never two on the device at once).
    device_.reset();
    try {
      device_ =
          std::make_unique<gpu::DeviceRenderScene>(device_context_, *world_, scene_options(next));
    } catch (const Error&) {
      // The host draws from now on, with the new fields: built here if it was not kept (if that
      // fails too, the old fields come back to the host).
      if (!live_) {
        try {
          live_ = std::make_unique<DynamicRenderScene>(*world_, scene_options(next));
        } catch (const Error&) {
          make_scene();
          throw;
        }
      }
      settings_ = next;
      throw;
    }
  }
  settings_ = next;
}

void DemoWorld::save(const std::filesystem::path& path) const {
  save_world(*world_, *world_->voxels.bounds(), path);
}

}  // namespace voxfield::demo
