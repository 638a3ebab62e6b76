// voxfield GPU backend — a render scene whose fields are computed, kept and packed on the device
// (gpu_render.h: DeviceRenderScene).
//
// The skip and lighting fields are gpu::DynamicFields; the ray marcher's cells are packed from
// their buffers and the world's brick pool by shaders/scene_pack.comp. Each (re)pack is two
// submits: the listed chunks' summaries (8 bytes each, read back), then — once the host has
// decided from them which chunks are stored voxel by voxel and given those slots, the rule
// RenderScene follows (scene_impl.h: place_chunk) — their chunk-table entries and cells.
#include <chrono>
#include <cstring>

#include "../shading.h"
#include "device_scene.h"
#include "gpu/split_buffer.h"
#include "render_shaders.h"
#include "voxfield/detail/assert.h"
#include "voxfield/gpu_render_vulkan.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The render box: `box`, else the world's bounds.
Box3i render_box(const World& world, const std::optional<Box3i>& box) {
  if (!box && !world.voxels.bounds())
    throw InvalidArgument("DeviceRenderScene: an unbounded world needs a render box");
  const Box3i b = box ? *box : *world.voxels.bounds();
  if (b.empty())
    throw InvalidArgument("DeviceRenderScene: nothing to render (empty box " + to_string(b) + ")");
  return b;
}

}  // namespace

using Impl = DeviceRenderScene::Impl;

Impl::Impl(std::shared_ptr<Context> c, const World& w, const RenderSceneOptions& options,
           const Box3i& render_box)
    : context(std::move(c)),
      ctx(context->impl()),
      world(w),
      box(render_box),
      table(box, w.voxels.chunk_edge()),
      chunk_volume(static_cast<std::uint32_t>(w.voxels.chunk_volume())),
      skip(context, w, skip_field_options(options, box)),
      skip_options(skip_field_options(options, box)),
      pack(ctx.kernel(shaders::scene_pack())),
      frames(*context) {
  // The lighting field rides on the skip field's resident world: one copy of the world.
  if (options.lighting_field) light.emplace(skip, light_field_options(options, box));
  // The pack reads both fields through the skip field's header: one domain, the box.
  VOXFIELD_ASSERT(!light || light->resident().domain == skip.resident().domain);
  skip_inv_scale = 1.0 / skip.resident().encoding.scale;
  if (light) light_inv_scale = 1.0 / light->resident().encoding.scale;
  const std::size_t n = table.chunk_count();
  // (16 bytes a chunk, bound whole: the skip field, a byte a voxel, outgrows its windows first.)
  info.assign(n, {L::VF_UNIFORM, 0, L::VF_UNIFORM, 0});
  skip_slots.slot.assign(n, L::VF_UNIFORM);
  light_slots.slot.assign(n, L::VF_UNIFORM);
  info_buf = Buffer(ctx, std::max<std::size_t>(n * 16, 16), kSceneBufferUsage, false);
  palette_buf = Buffer(ctx, 256 * 16, kSceneBufferUsage, false);
  dummy = Buffer(ctx, 16, kSceneBufferUsage, false);
  built.bytes_up = skip.last_upload_bytes() + (light ? light->last_upload_bytes() : 0);
  built.submits = light ? 2 : 1;
  std::vector<std::size_t> all(n);
  for (std::size_t i = 0; i < n; ++i) all[i] = i;
  const auto t0 = std::chrono::steady_clock::now();
  repack(all, true, built);
  built.scene_ms = ms_since(t0);
}

// The pack kernel's bindings (scene_pack.comp), `params` for the heat pass.
std::array<Binding, 25> Impl::bindings(Buffer* params) {
  const ResidentField s = skip.resident();
  Buffer* light_values = light ? light->resident().values : nullptr;
  const auto skip_parts = split_bindings(bound_or_dummy(&skip_arena), ctx);
  const auto light_parts = split_bindings(bound_or_dummy(&light_arena), ctx);
  const auto bricks = split_bindings(bound_or_dummy(s.bricks), ctx);
  const auto skip_values = split_bindings(*s.values, ctx);
  const auto light_field = split_bindings(bound_or_dummy(light_values), ctx);
  return {s.header,
          s.pages,
          bricks[0],
          skip_values[0],
          light_field[0],
          &bound_or_dummy(&items_buf),
          &bound_or_dummy(&summaries_buf),
          skip_parts[0],
          light_parts[0],
          &bound_or_dummy(params),
          skip_parts[1],
          skip_parts[2],
          skip_parts[3],
          light_parts[1],
          light_parts[2],
          light_parts[3],
          bricks[1],
          bricks[2],
          bricks[3],
          skip_values[1],
          skip_values[2],
          skip_values[3],
          light_field[1],
          light_field[2],
          light_field[3]};
}

L::ScenePackParams Impl::pack_params(std::uint32_t mode, std::size_t items) {
  L::ScenePackParams p{};
  const Vec3i first = table.first_chunk(), dims = table.chunk_dims();
  p.first_chunk = {first.x, first.y, first.z, table.shift()};
  p.chunk_dims = {dims.x, dims.y, dims.z, static_cast<std::int32_t>(chunk_volume)};
  p.mode = mode;
  p.items = static_cast<std::uint32_t>(items);
  p.has_light = light ? 1u : 0u;
  p.skip_background = skip.resident().background_bits & 0xFFu;
  p.light_background = light ? light->resident().background_bits & 0xFFu : 0u;
  p.part_shift = split_part_shift(ctx);
  return p;
}

void Impl::ensure_items(std::size_t items) {
  if (items_buf.size() < std::max<std::size_t>(items * 16, 16))
    items_buf = Buffer(ctx, std::max<std::size_t>(items * 16, 16), kSceneBufferUsage, false);
  if (summaries_buf.size() < std::max<std::size_t>(items * 8, 16))
    summaries_buf = Buffer(ctx, std::max<std::size_t>(items * 8, 16), kSceneBufferUsage, false);
}

void Impl::ensure_arena(Recorder& rec, Buffer& arena, std::vector<Buffer>& retired,
                        std::uint32_t slots, std::uint32_t live_slots, std::size_t slot_bytes) {
  const std::size_t bytes = std::max<std::size_t>(std::size_t{slots} * slot_bytes, 16);
  if (arena.handle() != VK_NULL_HANDLE && arena.size() >= bytes) return;
  // The shaders bind an arena as split_buffer.h's windows.
  check_split_binding(ctx, bytes, "DeviceRenderScene: an arena of its cells");
  const std::size_t capacity = split_capacity_bytes(ctx);
  // Half again for the edits to come, within what can be bound.
  const std::size_t grown =
      std::min(capacity, std::max(bytes, static_cast<std::size_t>(arena.size()) * 3 / 2));
  Buffer bigger(ctx, grown, kSceneBufferUsage, false);
  if (arena.handle() != VK_NULL_HANDLE) {
    // The old buffer lives in `retired` (reserved by the caller, so it does not move) until the
    // copy of its live slots has run.
    retired.push_back(std::move(arena));
    arena = std::move(bigger);
    if (live_slots > 0) rec.copy(retired.back(), 0, arena, 0, std::size_t{live_slots} * slot_bytes);
  } else {
    arena = std::move(bigger);
  }
}

void Impl::repack(const std::vector<std::size_t>& chunks, bool whole, UpdateStats& st) {
  if (chunks.empty()) return;
  const std::size_t n = chunks.size();
  ensure_items(n);
  std::vector<std::uint32_t> items(4 * n, 0);
  for (std::size_t k = 0; k < n; ++k) items[4 * k] = static_cast<std::uint32_t>(chunks[k]);
  // Submit 1: the summaries.
  std::vector<std::uint32_t> summaries(2 * n);
  {
    Buffer& upload = ctx.upload_buffer(n * 16);
    std::memcpy(upload.mapped(), items.data(), n * 16);
    Buffer& readback = ctx.readback_buffer(n * 8);
    Recorder rec(ctx);
    rec.copy(upload, 0, items_buf, 0, n * 16);
    rec.dispatch_strided(pack, bindings(nullptr), pack_params(L::VF_PACK_SUMMARISE, n),
                         static_cast<std::uint64_t>(n) * 64);
    rec.copy(summaries_buf, 0, readback, 0, n * 8);
    rec.submit();
    std::memcpy(summaries.data(), readback.mapped(), n * 8);
    st.bytes_up += n * 16;
    st.bytes_down += n * 8;
    ++st.submits;
  }
  // On the host: which chunks are stored voxel by voxel, their slots and table entries.
  const std::uint32_t skip_live = skip_slots.used, light_live = light_slots.used;
  std::vector<std::size_t> changed;
  std::vector<std::uint32_t> write;  // items of the cells' pass
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = chunks[k];
    const std::uint32_t range = summaries[2 * k];
    const std::uint32_t d_min = range & 0xFF, d_max = (range >> 8) & 0xFF;
    const std::uint32_t l_min = (range >> 16) & 0xFF, l_max = range >> 24;
    const ChunkView<std::uint8_t> v = world.voxels.chunk_view(table.chunk_coord(i));
    const bool dense_material = v.voxels != nullptr;
    skip_slots.place(i, d_min != d_max || dense_material);
    if (light) light_slots.place(i, l_min != l_max);
    // As RenderScene's entries (gpu_render.cpp: chunk_info): the skip slot, the uniform cell
    // (when the chunk has no slot) with the chunk's smallest distance, "no solid voxel" and
    // "materials stored voxel by voxel"; the lighting slot and uniform value.
    const std::uint32_t uniform_cell =
        skip_slots.slot[i] == L::VF_UNIFORM ? d_min | (std::uint32_t{v.uniform_value} << 8) : 0u;
    const std::array<std::uint32_t, 4> entry{
        skip_slots.slot[i],
        uniform_cell | (d_min << 16) | (summaries[2 * k + 1] == 0 ? 1u << 24 : 0u) |
            (dense_material ? 1u << 25 : 0u),
        light ? light_slots.slot[i] : L::VF_UNIFORM, light ? l_min : 0u};
    if (whole || entry != info[i]) {
      info[i] = entry;
      changed.push_back(i);
    }
    if (entry[0] != L::VF_UNIFORM || entry[2] != L::VF_UNIFORM)
      write.insert(write.end(), {static_cast<std::uint32_t>(i), entry[0], entry[2], 0u});
  }
  // Submit 2: the entries, the palette when it changed, the cells.
  const bool palette_changed = whole || world.palette != palette;
  std::vector<Buffer> retired;  // replaced arenas, until the copies out of them have run
  Recorder rec(ctx);
  retired.reserve(2);
  ensure_arena(rec, skip_arena, retired, skip_slots.used, skip_live, std::size_t{chunk_volume} * 2);
  ensure_arena(rec, light_arena, retired, light ? light_slots.used : 0, light_live, chunk_volume);
  const std::size_t items_bytes = write.size() * 4;
  std::size_t staged = items_bytes + changed.size() * 16 + (palette_changed ? 256 * 16 : 0);
  Buffer& upload = ctx.upload_buffer(std::max<std::size_t>(staged, 16));
  auto* base = static_cast<std::uint8_t*>(upload.mapped());
  std::size_t at = 0;
  if (items_bytes > 0) std::memcpy(base, write.data(), items_bytes);
  at = items_bytes;
  std::vector<VkBufferCopy> info_copies, palette_copies, item_copies;
  if (items_bytes > 0) item_copies.push_back({0, 0, items_bytes});
  for (std::size_t i : changed) {
    std::memcpy(base + at, info[i].data(), 16);
    info_copies.push_back({at, i * 16, 16});
    at += 16;
  }
  if (palette_changed) {
    palette = world.palette;
    std::vector<float> linear(256 * 4, 0.0f);
    for (int m = 0; m < 256; ++m) {
      const Rgba& c = palette[static_cast<std::size_t>(m)];
      const std::size_t at4 = static_cast<std::size_t>(4 * m);
      linear[at4] = render_detail::srgb_to_linear(c.r);
      linear[at4 + 1] = render_detail::srgb_to_linear(c.g);
      linear[at4 + 2] = render_detail::srgb_to_linear(c.b);
    }
    std::memcpy(base + at, linear.data(), 256 * 16);
    palette_copies.push_back({at, 0, 256 * 16});
    at += 256 * 16;
  }
  rec.copy({{&upload, &items_buf, item_copies},
            {&upload, &info_buf, info_copies},
            {&upload, &palette_buf, palette_copies}});
  if (!write.empty())
    rec.dispatch_strided(pack, bindings(nullptr), pack_params(L::VF_PACK_WRITE, write.size() / 4),
                         static_cast<std::uint64_t>(write.size() / 4) * (chunk_volume / 4));
  rec.submit();
  st.bytes_up += at;
  ++st.submits;
  st.chunks_repacked += n;
  forget_moved_buffers();
}

void Impl::forget_moved_buffers() {
  // The frames' descriptor sets name these buffers (the heat pass binds the pack's): when one was
  // replaced — an arena grown by a pack, the brick pool by the fields' update — they go.
  const std::array<VkBuffer, 5> bound{skip.resident().bricks->handle(), skip_arena.handle(),
                                      light_arena.handle(), items_buf.handle(),
                                      summaries_buf.handle()};
  if (bound != bound_handles) {
    bound_handles = bound;
    frames.buffers_replaced();
  }
}

FrameScene Impl::frame_scene() {
  FrameScene f;
  f.world = &world;
  f.box = box;
  f.table = table;
  f.chunk_volume = chunk_volume;
  f.metric = skip_options.metric;
  f.skip_inv_scale = skip_inv_scale;
  f.light_inv_scale = light_inv_scale;
  f.has_light = light.has_value();
  f.skip_options = skip_options;
  f.id = 1;
  f.generation = generation;
  f.info = &info_buf;
  f.skip = &bound_or_dummy(&skip_arena);
  f.light = &bound_or_dummy(&light_arena);
  f.palette = &palette_buf;
  f.record_heat = [this](Recorder& rec, Buffer& params, int z) {
    L::ScenePackParams p = pack_params(L::VF_PACK_HEAT, 0);
    p.slice_z = z;
    rec.dispatch_strided(pack, bindings(&params), p,
                         static_cast<std::uint64_t>(box.size().x) * box.size().y);
  };
  return f;
}

std::vector<std::uint8_t> Impl::read_back(Buffer& b, std::size_t bytes) {
  Buffer& readback = ctx.readback_buffer(std::max<std::size_t>(bytes, 16));
  Recorder rec(ctx);
  if (bytes > 0) rec.copy(b, 0, readback, 0, bytes);
  rec.submit();
  const auto* p = static_cast<const std::uint8_t*>(readback.mapped());
  return std::vector<std::uint8_t>(p, p + bytes);
}

DeviceRenderScene::DeviceRenderScene(std::shared_ptr<Context> context, const World& world,
                                     RenderSceneOptions options, std::optional<Box3i> box) {
  if (!context) throw InvalidArgument("gpu::DeviceRenderScene: no context");
  const auto t0 = std::chrono::steady_clock::now();
  impl_ = std::make_unique<Impl>(std::move(context), world, options, render_box(world, box));
  impl_->built.field_ms = ms_since(t0) - impl_->built.scene_ms;
}

DeviceRenderScene::~DeviceRenderScene() = default;

DeviceRenderScene::UpdateStats DeviceRenderScene::update(const DirtyRegions& dirty) {
  Impl& s = *impl_;
  UpdateStats st;
  if (dirty.empty()) return st;
  const auto t0 = std::chrono::steady_clock::now();
  st.voxels_recomputed += s.skip.update(dirty).voxels_recomputed;
  st.bytes_up += s.skip.last_upload_bytes();
  ++st.submits;
  if (s.light) {
    st.voxels_recomputed += s.light->update(dirty).voxels_recomputed;
    st.bytes_up += s.light->last_upload_bytes();
    ++st.submits;
  }
  st.field_ms = ms_since(t0);
  // A changed voxel moves field values up to the larger reach away and its own material: re-pack
  // the chunks of every changed box grown by it (as DynamicRenderScene re-reads them).
  Vec3i reach = s.skip.reach();
  if (s.light) {
    const Vec3i l = s.light->reach();
    reach = {std::max(reach.x, l.x), std::max(reach.y, l.y), std::max(reach.z, l.z)};
  }
  std::vector<Box3i> boxes = dirty.boxes();
  for (Box3i& b : boxes) b = Box3i{b.begin - reach, b.end + reach};
  const std::vector<std::size_t> chunks = s.table.chunks_touching(boxes);
  const auto t1 = std::chrono::steady_clock::now();
  s.repack(chunks, false, st);
  s.forget_moved_buffers();  // (also when nothing was packed: the fields' pool may have moved)
  ++s.generation;
  st.scene_ms = ms_since(t1);
  return st;
}

const DeviceRenderScene::UpdateStats& DeviceRenderScene::build_stats() const {
  return impl_->built;
}

const Box3i& DeviceRenderScene::box() const {
  return impl_->box;
}

Context& DeviceRenderScene::context() {
  return *impl_->context;
}

Image DeviceRenderScene::render(const Camera& camera, const RenderOptions& options,
                                RenderStats* stats, std::vector<PassTiming>* timings) {
  Impl& s = *impl_;
  return render_and_read(s.ctx, s.frames, s.frame_scene(), nullptr, camera, options, stats,
                         timings);
}

VkBuffer record_render(DeviceRenderScene& scene, VkCommandBuffer cmd, const Camera& camera,
                       const RenderOptions& options, PixelOrder order) {
  DeviceRenderScene::Impl& s = scene.impl();
  const FrameScene f = s.frame_scene();
  check_frame(f, options);  // before computing an approximation for a frame refused
  s.frames.prepare_approximation(f, options);
  Recorder rec(s.ctx, cmd, s.frames.sets());
  s.frames.record_render(rec, f, camera, options, order == PixelOrder::kBgra, /*timed=*/false);
  rec.expose(s.frames.pixels(), VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
  return s.frames.pixels().handle();
}

}  // namespace voxfield::gpu
