// voxfield GPU backend — what a DeviceRenderScene keeps (device_scene.cpp; gpu_render.h). Private
// to the render module and its tests, which read its buffers back to compare them cell by cell
// with a host RenderScene.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "frames.h"
#include "shaders/layout.h"
#include "voxfield/gpu_distance.h"

namespace voxfield::gpu {

// Slots of an arena, handed out as RenderScene's BrickedChunks hands them out: the most recently
// freed first, else the next never used.
struct Slots {
  std::vector<std::uint32_t> slot;  // per chunk, or VF_UNIFORM
  std::vector<std::uint32_t> free;
  std::uint32_t used = 0;
  // Whether chunk i changed hands: given a slot it did not have, or losing one.
  bool place(std::size_t i, bool dense) {
    std::uint32_t& s = slot[i];
    if (dense == (s != layout::VF_UNIFORM)) return false;
    if (dense) {
      if (!free.empty()) {
        s = free.back();
        free.pop_back();
      } else {
        s = used++;
      }
    } else {
      free.push_back(s);
      s = layout::VF_UNIFORM;
    }
    return true;
  }
};

struct DeviceRenderScene::Impl {
  std::shared_ptr<Context> context;
  Context::Impl& ctx;
  const World& world;
  Box3i box;
  render_detail::ChunkTable table;
  std::uint32_t chunk_volume;
  DynamicField skip;
  std::optional<DynamicField> light;
  DistanceOptions skip_options;
  double skip_inv_scale = 1, light_inv_scale = 0.25;
  const Kernel& pack;
  Frames frames;
  std::vector<std::array<std::uint32_t, 4>> info;  // the chunk table as on the device
  Slots skip_slots, light_slots;
  Buffer info_buf, skip_arena, light_arena, palette_buf, items_buf, summaries_buf, dummy;
  Palette palette{};
  std::uint64_t generation = 1;
  UpdateStats built;
  std::array<VkBuffer, 5> bound_handles{};  // what the frames' sets last saw (repack)

  Impl(std::shared_ptr<Context> c, const World& w, const RenderSceneOptions& options,
       const Box3i& box);

  // Summarises `chunks` (table indices, ascending), places them, and packs the entries and cells
  // of those that changed. Counts into `st`.
  void repack(const std::vector<std::size_t>& chunks, bool whole, UpdateStats& st);
  // What a frame reads.
  FrameScene frame_scene();
  // Resets the frames' descriptor sets when a buffer they may name was replaced.
  void forget_moved_buffers();
  // The first `bytes` of a buffer of the scene, read back (tests; one submit).
  std::vector<std::uint8_t> read_back(Buffer& b, std::size_t bytes);

 private:
  Buffer& bound_or_dummy(Buffer* b) { return b && b->handle() != VK_NULL_HANDLE ? *b : dummy; }
  std::array<Binding, 25> bindings(Buffer* params);
  layout::ScenePackParams pack_params(std::uint32_t mode, std::size_t items);
  void ensure_items(std::size_t items);
  // Grows an arena to hold `slots` slots of `slot_bytes` (InvalidArgument beyond the device's
  // storage-buffer range), its `live_slots` copied on the device.
  void ensure_arena(Recorder& rec, Buffer& arena, std::vector<Buffer>& retired, std::uint32_t slots,
                    std::uint32_t live_slots, std::size_t slot_bytes);
};

}  // namespace voxfield::gpu
