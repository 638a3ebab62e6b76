// Scenes whose fields are computed, kept and packed on the device (gpu::DeviceRenderScene) against
// the host's DynamicRenderScene drawn by a SceneRenderer: the same shader reading the same values,
// so every frame must be equal pixel for pixel, through every view and a stream of edits — and
// only the world's changed chunks go up, only the packed chunks' summaries come back
// (voxfield_gpu_tests; validation layer on, synchronisation validation included).
#include <gtest/gtest.h>

#include "gpu_suite.h"
#include "render/gpu/device_scene.h"  // its buffers, read back to compare cell by cell
#include "render/scene_impl.h"
#include "voxfield/edit.h"
#include "voxfield/gpu_render.h"
#include "voxfield/gpu_render_vulkan.h"

using namespace voxfield;
using test::gpu_tests_wanted;
using test::random_world;
using test::validated_context;

namespace {

// The frames compared: the shaded view with ambient occlusion and soft shadows from two cameras,
// the chunk view, the distance view on three cuts, and the error view; and from straight above.
struct Views {
  std::vector<Camera> cameras;
  std::vector<RenderOptions> options;
};

Views views_of(const Box3i& box, bool lighting) {
  Views v;
  v.cameras = {Camera::framing(box, 1.5)};
  Camera low = Camera::framing(box, 1.2);
  low.eye = {box.begin.x - 9.0, box.begin.y - 7.0, box.end.z * 0.6};
  v.cameras.push_back(low);
  v.cameras.push_back(Camera::top(box, 80.0 / 56.0));  // the distance view's every column
  RenderOptions o;
  o.width = 80;
  o.height = 56;
  o.ambient_occlusion = lighting;
  o.soft_shadows = lighting;
  v.options.push_back(o);
  RenderOptions chunks = o;
  chunks.view = RenderView::kChunks;
  v.options.push_back(chunks);
  for (int z : {box.begin.z + 2, (box.begin.z + box.end.z) / 2, box.end.z - 1}) {
    RenderOptions d = o;
    d.view = RenderView::kDistance;
    d.slice_z = z;
    v.options.push_back(d);
  }
  RenderOptions error = o;
  error.view = RenderView::kError;
  error.error_algorithm = Algorithm::kJfaSeed;
  v.options.push_back(error);
  return v;
}

void expect_same_frames(gpu::DeviceRenderScene& device, gpu::SceneRenderer& host,
                        const Views& views, const std::string& what) {
  for (std::size_t c = 0; c < views.cameras.size(); ++c)
    for (const RenderOptions& o : views.options)
      EXPECT_EQ(device.render(views.cameras[c], o).rgb, host.render(views.cameras[c], o).rgb)
          << what << ", camera " << c << ", view " << static_cast<int>(o.view) << ", slice "
          << o.slice_z.value_or(-1);
}

// Every chunk's table entry and every voxel's cell and lighting value on the device equal the
// host scene's: the values a frame could read, and those it reads nowhere (the voxels of a chunk
// outside the box hold the fields' background on both).
void expect_same_cells(gpu::DeviceRenderScene& device, const RenderScene& host_scene,
                       const std::string& what) {
  gpu::DeviceRenderScene::Impl& d = device.impl();
  const RenderScene::Impl& h = host_scene.impl();
  const std::size_t n = h.table.chunk_count();
  ASSERT_EQ(d.table.chunk_count(), n);
  const auto words = [](const std::vector<std::uint8_t>& bytes) {
    std::vector<std::uint32_t> w(bytes.size() / 4);
    std::memcpy(w.data(), bytes.data(), w.size() * 4);
    return w;
  };
  const std::vector<std::uint32_t> info = words(d.read_back(d.info_buf, n * 16));
  const std::vector<std::uint8_t> skip =
      d.read_back(d.skip_arena, std::size_t{d.skip_slots.used} * d.chunk_volume * 2);
  const std::vector<std::uint8_t> light =
      h.has_light ? d.read_back(d.light_arena, std::size_t{d.light_slots.used} * d.chunk_volume)
                  : std::vector<std::uint8_t>();
  int bad = 0;
  for (std::size_t i = 0; i < n && bad < 5; ++i) {
    const std::uint32_t* e = &info[4 * i];
    const std::string chunk = what + ", chunk " + to_string(h.table.chunk_coord(i));
    // The same chunks stored voxel by voxel, in the same slots (both hand them out alike).
    const auto slot = [](std::uint32_t host_slot) {
      return host_slot == BrickedChunks<std::uint16_t>::kUniform ? gpu::layout::VF_UNIFORM
                                                                 : host_slot;
    };
    EXPECT_EQ(e[0], slot(h.skip.cells.slot[i])) << chunk;
    if (h.has_light) {
      EXPECT_EQ(e[2], slot(h.light.slot[i])) << chunk;
    }
    EXPECT_EQ((e[1] >> 16) & 0xFF, h.skip.chunk_min[i]) << chunk;
    EXPECT_EQ((e[1] >> 24) & 1, h.empty_chunk[i]) << chunk;
    EXPECT_EQ((e[1] >> 25) & 1, h.dense_material[i]) << chunk;
    for (std::uint32_t k = 0; k < d.chunk_volume; ++k) {
      std::uint16_t cell = static_cast<std::uint16_t>(e[1] & 0xFFFF);
      if (e[0] != gpu::layout::VF_UNIFORM)
        std::memcpy(&cell, &skip[(std::size_t{e[0]} * d.chunk_volume + k) * 2], 2);
      if (cell != h.skip.read(i, k)) {
        ADD_FAILURE() << chunk << ", brick index " << k << ": cell " << cell << " on the device, "
                      << h.skip.read(i, k) << " on the host";
        ++bad;
        break;
      }
      if (!h.has_light) continue;
      const std::uint8_t l = e[2] == gpu::layout::VF_UNIFORM
                                 ? static_cast<std::uint8_t>(e[3])
                                 : light[std::size_t{e[2]} * d.chunk_volume + k];
      if (l != h.light.read(i, k)) {
        ADD_FAILURE() << chunk << ", brick index " << k << ": lighting " << int{l}
                      << " on the device, " << int{h.light.read(i, k)} << " on the host";
        ++bad;
        break;
      }
    }
  }
}

}  // namespace

TEST(Gpu, DeviceScenesDrawWhatHostScenesDrawThroughEdits) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  struct Case {
    Vec3i size;
    Metric metric;
    double clamp;
    bool lighting;
  };
  // A box that ends inside chunks (the fields' background fills them), each skip metric, and a
  // scene without a lighting field.
  for (const Case& k : {Case{{61, 45, 30}, Metric::kManhattan, 10, true},
                        Case{{48, 40, 24}, Metric::kEuclidean, 6, true},
                        Case{{40, 32, 24}, Metric::kChebyshev, 0, false}}) {
    const std::string what = std::string(metric_name(k.metric)) + " " + to_string(k.size);
    World w = random_world(k.size, 8, 0.004, 17);
    w.voxels.fill(Box3i{{0, 0, 0}, {k.size.x, k.size.y, 3}}, 120);
    RenderSceneOptions so = DynamicRenderScene::default_options();
    so.skip_metric = k.metric;
    so.skip_max_distance_vox = k.clamp;
    so.lighting_field = k.lighting;
    so.lighting_max_distance_vox = 6;
    DynamicRenderScene live(w, so);
    gpu::SceneRenderer host(ctx);
    host.sync(live.scene());
    const gpu::Counters before_build = ctx->counters();
    gpu::DeviceRenderScene device(ctx, w, so);
    const gpu::DeviceRenderScene::UpdateStats& built = device.build_stats();
    // The build's counts are what crossed: the world and the lists up, the summaries down.
    EXPECT_EQ(ctx->counters().bytes_uploaded - before_build.bytes_uploaded,
              static_cast<std::int64_t>(built.bytes_up))
        << what;
    EXPECT_EQ(ctx->counters().bytes_downloaded - before_build.bytes_downloaded,
              static_cast<std::int64_t>(built.bytes_down))
        << what;
    EXPECT_EQ(ctx->counters().submits - before_build.submits, built.submits) << what;
    // Every chunk of the box is packed once.
    EXPECT_EQ(
        built.chunks_repacked,
        static_cast<std::size_t>((k.size.x + 7) / 8 * ((k.size.y + 7) / 8) * ((k.size.z + 7) / 8)))
        << what;
    EXPECT_EQ(built.bytes_down, built.chunks_repacked * 8) << what;  // (summaries alone)
    const Views views = views_of(live.scene().box(), k.lighting);
    expect_same_cells(device, live.scene(), what + ", built");
    expect_same_frames(device, host, views, what + ", built");

    std::mt19937 rng(5);
    auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
    DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
    for (int batch = 0; batch < 4; ++batch) {
      for (int e = 0; e < 3; ++e) {
        const EditOp op = uni(0, 2) == 0 ? EditOp::kCarve
                          : uni(0, 1)    ? EditOp::kPlace
                                         : EditOp::kPaint;
        apply_edit(w,
                   {op,
                    SphereBrush{{uni(0, k.size.x - 1) * 1.0, uni(0, k.size.y - 1) * 1.0,
                                 uni(0, k.size.z - 1) * 1.0},
                                uni(1, 5) * 1.0},
                    static_cast<std::uint8_t>(uni(1, 255))},
                   &dirty);
      }
      if (batch == 2) w.palette[120] = Rgba{200, 30, 40, 255};  // a palette edit travels too
      const std::int64_t world_chunks = static_cast<std::int64_t>(dirty.boxes().size());
      live.update(dirty);
      host.sync(live.scene());
      const gpu::Counters before = ctx->counters();
      const gpu::DeviceRenderScene::UpdateStats st = device.update(dirty);
      const gpu::Counters after = ctx->counters();
      dirty.clear();
      const std::string at = what + ", batch " + std::to_string(batch);
      // Down: only the summaries, 8 bytes per packed chunk — no field value.
      EXPECT_EQ(after.bytes_downloaded - before.bytes_downloaded,
                static_cast<std::int64_t>(st.chunks_repacked * 8))
          << at;
      EXPECT_EQ(after.bytes_downloaded - before.bytes_downloaded,
                static_cast<std::int64_t>(st.bytes_down))
          << at;
      EXPECT_EQ(after.bytes_uploaded - before.bytes_uploaded,
                static_cast<std::int64_t>(st.bytes_up))
          << at;
      // Up: the changed world chunks once, however many fields (a chunk's bytes and its page
      // entry), the chunk lists (16 bytes an item, twice), the table entries and, when it changed,
      // the palette.
      const std::int64_t fields = k.lighting ? 2 : 1;
      EXPECT_LE(after.bytes_uploaded - before.bytes_uploaded,
                world_chunks * (512 + 4) +
                    static_cast<std::int64_t>(st.chunks_repacked) * (16 + 16 + 16) +
                    (batch == 2 ? 256 * 16 : 0))
          << at;
      EXPECT_EQ(after.submits - before.submits, st.submits) << at;
      EXPECT_EQ(st.submits, fields + 2) << at;
      expect_same_cells(device, live.scene(), at);
      expect_same_frames(device, host, views, at);
    }
  }
  test::expect_no_validation_messages(*ctx);
}

TEST(Gpu, DeviceScenesOfUniformWorldsAndBadInput) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  // No chunk stored voxel by voxel: an empty world, then a world of whole-chunk blocks. The
  // device's brick pool is empty; the frames still equal the host's.
  World w(8, Box3i::from_size({32, 32, 16}));
  RenderSceneOptions so = DynamicRenderScene::default_options();
  so.skip_max_distance_vox = 12;
  so.lighting_max_distance_vox = 5;
  for (int round = 0; round < 2; ++round) {
    if (round == 1) w.voxels.fill(Box3i{{8, 8, 0}, {24, 16, 8}}, 9);
    DynamicRenderScene live(w, so);
    gpu::SceneRenderer host(ctx);
    host.sync(live.scene());
    gpu::DeviceRenderScene device(ctx, w, so);
    const Views views = views_of(live.scene().box(), true);
    if (round == 0) {  // nothing varies: no chunk has a slot
      EXPECT_EQ(device.impl().skip_slots.used, 0u);
      EXPECT_EQ(device.impl().light_slots.used, 0u);
    }
    expect_same_cells(device, live.scene(), "round " + std::to_string(round));
    expect_same_frames(device, host, views, "round " + std::to_string(round));
  }
  World unbounded(8);
  unbounded.voxels.set({1, 1, 1}, 3);
  EXPECT_THROW(gpu::DeviceRenderScene(ctx, unbounded), InvalidArgument);
  EXPECT_THROW(gpu::DeviceRenderScene(nullptr, w), InvalidArgument);
  RenderSceneOptions far = so;
  far.skip_max_distance_vox = 300;  // beyond u8's reach
  EXPECT_THROW(gpu::DeviceRenderScene(ctx, w, far), InvalidArgument);
  gpu::DeviceRenderScene device(ctx, w, so);
  RenderOptions bad;
  bad.view = RenderView::kDistance;
  bad.slice_z = 99;
  EXPECT_THROW(device.render(Camera::framing(device.box(), 1.5), bad), InvalidArgument);
  test::expect_no_validation_messages(*ctx);
}

TEST(Gpu, DeviceScenesOfABoxThatStartsAndEndsInsideChunks) {
  // A render box that is not the world's bounds and whose faces cut through chunks on every side:
  // the first chunks begin before the fields' domain, so the pack reads the fields' background
  // there, as a host Grid does.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  World w = random_world({48, 40, 32}, 8, 0.01, 9);
  const Box3i box{{3, 5, 2}, {45, 37, 29}};
  RenderSceneOptions so = DynamicRenderScene::default_options();
  so.skip_max_distance_vox = 7;
  so.lighting_max_distance_vox = 4;
  const RenderScene host_scene(w, so, box);
  gpu::SceneRenderer host(ctx);
  host.sync(host_scene);
  gpu::DeviceRenderScene device(ctx, w, so, box);
  EXPECT_EQ(device.box(), box);
  expect_same_cells(device, host_scene, "box " + to_string(box));
  expect_same_frames(device, host, views_of(box, true), "box " + to_string(box));
  test::expect_no_validation_messages(*ctx);
}

TEST(Gpu, ArenasAndImagesPastTheStorageBufferRangeAreBoundInWindows) {
  // On a device whose storage-buffer range is lowered (ContextOptions, as a user sharing a device
  // would) below a scene's cell arenas and its image, the ray marcher and the packing pass reach
  // them through four windows each (src/gpu/split_buffer.h). Every frame equals the one a device
  // binding them whole draws, pixel for pixel — host scenes, device scenes and the error view's
  // approximation alike, through edits that grow the arenas into further windows. What four
  // windows cannot hold is refused by name before anything is drawn.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  // Windows of 16 KiB, 64 KiB in four.
  // (Named, not structured, bindings: the lambdas below capture them, which Clang 14 refuses.)
  const test::CappedAndWhole contexts = test::capped_and_whole(32 * 1024 - 4);
  const std::shared_ptr<gpu::Context>& small = contexts.small;
  const std::shared_ptr<gpu::Context>& whole = contexts.whole;
  constexpr std::size_t kWindow = 16 * 1024;

  // 54 chunks of 8^3 (1 KiB of cells, 512 bytes of lighting each); thin across x, so that the
  // device's clamped fields are computed in slabs on this range.
  World w = random_world({72, 24, 16}, 8, 0.004, 23);
  w.voxels.fill(Box3i{{0, 0, 0}, {72, 24, 3}}, 120);
  w.voxels.fill(Box3i{{48, 0, 0}, {72, 24, 16}}, 0);  // clear air, for edits to grow into
  RenderSceneOptions so = DynamicRenderScene::default_options();
  so.skip_max_distance_vox = 6;
  so.lighting_max_distance_vox = 6;
  DynamicRenderScene live(w, so);
  const auto skip_bytes = [&] {
    const RenderScene::Impl& h = live.scene().impl();
    return std::size_t{h.skip.cells.slots_used} * h.skip.cells.slot_bytes();
  };
  const auto light_bytes = [&] {
    const RenderScene::Impl& h = live.scene().impl();
    return std::size_t{h.light.slots_used} * h.light.slot_bytes();
  };
  ASSERT_GT(skip_bytes(), 2 * kWindow) << "the cells span three windows";
  ASSERT_LT(skip_bytes(), 3 * kWindow);
  ASSERT_GT(light_bytes(), kWindow) << "the lighting two";

  const Box3i box = live.scene().box();
  Views views = views_of(box, true);
  for (RenderOptions& o : views.options) {
    o.width = 128;  // 53 248 bytes of pixels: four windows
    o.height = 104;
    // The error view's approximation on the host (brute force), its arena in windows.
    o.error_algorithm = Algorithm::kBruteChunked;
  }
  gpu::SceneRenderer host_small(small), host_whole(whole);
  gpu::DeviceRenderScene device_small(small, w, so);
  const auto expect_same = [&](const std::string& what) {
    host_small.sync(live.scene());
    host_whole.sync(live.scene());
    for (std::size_t c = 0; c < views.cameras.size(); ++c)
      for (const RenderOptions& o : views.options) {
        const std::string at = what + ", camera " + std::to_string(c) + ", view " +
                               render_view_name(o.view) + ", slice " +
                               std::to_string(o.slice_z.value_or(-1));
        const Image reference = host_whole.render(views.cameras[c], o);
        EXPECT_EQ(host_small.render(views.cameras[c], o).rgb, reference.rgb) << "host, " << at;
        EXPECT_EQ(device_small.render(views.cameras[c], o).rgb, reference.rgb) << "device, " << at;
      }
  };
  expect_same("built");

  // Blocks placed in the clear air: new chunks stored voxel by voxel, the arenas grow into a
  // fourth window (the host scene's and the device scene's alike).
  DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
  const std::size_t before = skip_bytes();
  for (int y = 4; y < 24; y += 8)
    apply_edit(w, {EditOp::kPlace, SphereBrush{{64.5, y + 0.5, 8.5}, 3.5}, 7}, &dirty);
  live.update(dirty);
  device_small.update(dirty);
  dirty.clear();
  ASSERT_GT(skip_bytes(), 3 * kWindow) << "from " << before << " bytes";
  ASSERT_LE(skip_bytes(), 4 * kWindow);
  expect_same("after edits");
  test::expect_no_validation_messages(*small);
  test::expect_no_validation_messages(*whole);

  // Past four windows: refused by name, on each path, and the next frame that fits still draws.
  const auto expect_refused = [](const auto& call, const std::string& what) {
    try {
      call();
      ADD_FAILURE() << what << " was drawn past what the device binds";
    } catch (const InvalidArgument& e) {
      EXPECT_NE(std::string(e.what()).find("more than this device binds"), std::string::npos)
          << what << ": " << e.what();
    }
  };
  World big = random_world({64, 64, 32}, 8, 0.004, 29);  // 256 chunks: 256 KiB of cells
  const RenderScene big_scene(big, so);
  const Camera cam = Camera::framing(big_scene.box(), 1.5);
  RenderOptions o;
  o.width = 64;
  o.height = 48;
  expect_refused([&] { (void)gpu::render(*small, big_scene, cam, o); }, "a host scene");
  // (A device scene's skip field, a byte for every voxel of the box, outgrows the windows before
  // its arenas, two bytes for each voxel of the chunks that vary, do.)
  expect_refused([&] { gpu::DeviceRenderScene(small, big, so); }, "a device scene");
  // A host scene's chunk table, 16 bytes a chunk bound whole: 2 048 chunks of air are one word
  // past the range.
  const World air(8, Box3i::from_size({128, 128, 64}));
  const RenderScene air_scene(air, so);
  expect_refused([&] { (void)gpu::render(*small, air_scene, cam, o); }, "a chunk table");
  o.width = 160;  // 76 800 bytes of pixels
  o.height = 120;
  expect_refused([&] { (void)host_small.render(views.cameras[0], o); }, "an image");
  EXPECT_EQ(host_small.render(views.cameras[0], views.options[0]).rgb,
            host_whole.render(views.cameras[0], views.options[0]).rgb);
  test::expect_no_validation_messages(*small);
}
