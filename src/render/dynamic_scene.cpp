// voxfield renderer — a scene that follows its world through edits.
//
// Both render fields are DynamicDistanceFields, so after an edit they are bit-identical to
// rebuilds; the scene then re-reads every chunk within the larger field reach of a changed voxel —
// exactly the chunks whose field values or materials can differ — and nothing else.
#include <chrono>

#include "scene_impl.h"
#include "voxfield/error.h"

namespace voxfield {
namespace {

const World& bounded(const World& world) {
  if (!world.voxels.bounds())
    throw InvalidArgument(
        "DynamicRenderScene: the world must be bounded (its bounds are the render box)");
  if (world.voxels.bounds()->empty())
    throw InvalidArgument("DynamicRenderScene: the world's bounds are empty");
  return world;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

RenderSceneOptions DynamicRenderScene::default_options() {
  RenderSceneOptions o;
  o.skip_metric = Metric::kManhattan;
  o.skip_max_distance_vox = 32;
  return o;
}

DynamicRenderScene::DynamicRenderScene(const World& world, RenderSceneOptions options)
    : world_(&bounded(world)),
      skip_(world, skip_field_options(options, *world.voxels.bounds())),
      light_(options.lighting_field
                 ? std::optional<DynamicDistanceField>(
                       std::in_place, world, light_field_options(options, *world.voxels.bounds()))
                 : std::nullopt),
      scene_(world, skip_.field(), light_ ? &light_->field() : nullptr) {}

DynamicRenderScene::UpdateStats DynamicRenderScene::update(const DirtyRegions& dirty) {
  UpdateStats st;
  if (dirty.empty()) return st;
  const auto t0 = std::chrono::steady_clock::now();
  st.voxels_recomputed += skip_.update(dirty).voxels_recomputed;
  if (light_) st.voxels_recomputed += light_->update(dirty).voxels_recomputed;
  st.field_ms = ms_since(t0);

  // A changed voxel moves field values up to `reach` away and its own material: re-read the
  // chunks of every changed box grown by the larger reach.
  Vec3i reach = skip_.reach();
  if (light_) {
    const Vec3i l = light_->reach();
    reach = {std::max(reach.x, l.x), std::max(reach.y, l.y), std::max(reach.z, l.z)};
  }
  std::vector<Box3i> boxes = dirty.boxes();
  for (Box3i& b : boxes) b = Box3i{b.begin - reach, b.end + reach};
  const auto t1 = std::chrono::steady_clock::now();
  st.chunks_changed = scene_.update(skip_.field(), light_ ? &light_->field() : nullptr, boxes);
  st.scene_ms = ms_since(t1);
  return st;
}

}  // namespace voxfield
