// voxfield tests — the edited scene both halves of the render executor's tests draw
// (test_render.cpp on the CPU executor, test_gpu_render.cpp on a device): a world, its
// DynamicRenderScene with a clamped skip field, a small frame with a camera framing it, and one
// edit that a SceneView must follow as a scene built afresh shows it.
#pragma once

#include <utility>

#include "voxfield/edit.h"
#include "voxfield/render.h"
#include "voxfield/world.h"

namespace voxfield::test {

class ExecutorScene {
 public:
  // `world` at least 26 x 22 x 18 voxels (the edit's sphere fits inside).
  explicit ExecutorScene(World world)
      : world_(std::move(world)),
        live_(world_, skip_options()),
        camera_(Camera::framing(live_.scene().box(), 1.5)) {
    options_.width = 64;
    options_.height = 48;
  }
  // live_ keeps a reference to world_.
  ExecutorScene(const ExecutorScene&) = delete;
  ExecutorScene& operator=(const ExecutorScene&) = delete;

  const RenderScene& scene() const { return live_.scene(); }
  const Camera& camera() const { return camera_; }
  const RenderOptions& options() const { return options_; }

  // Places a sphere of material 77 and brings the live scene up to date; returns the scene built
  // afresh from the edited world and the live fields.
  RenderScene edit() {
    DirtyRegions dirty(world_.voxels.chunk_edge(), DirtyRegions::Track::kAnyChange);
    apply_edit(world_, {EditOp::kPlace, SphereBrush{{20, 16, 12}, 5}, 77}, &dirty);
    live_.update(dirty);
    return RenderScene(world_, live_.skip_field(), live_.light_field());
  }

 private:
  static RenderSceneOptions skip_options() {
    RenderSceneOptions so = DynamicRenderScene::default_options();
    so.skip_max_distance_vox = 8;
    return so;
  }

  World world_;
  DynamicRenderScene live_;
  Camera camera_;
  RenderOptions options_;
};

}  // namespace voxfield::test
