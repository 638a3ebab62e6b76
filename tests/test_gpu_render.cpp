// The Vulkan ray marcher against the CPU renderer frame for frame, and resident scenes that follow
// edits copying only their changed chunks (voxfield_gpu_tests; the validation layer on, with
// synchronisation validation, and not a single message from it).
#include <gtest/gtest.h>

#include "csg_examples.h"
#include "executor_scene.h"
#include "gpu_suite.h"
#include "image_compare.h"
#include "voxfield/csg_compile.h"
#include "voxfield/edit.h"
#include "voxfield/gpu_render.h"
#include "voxfield/gpu_render_vulkan.h"
#include "voxfield/render_executor.h"

using namespace voxfield;
using test::gpu_tests_wanted;
using test::random_world;
using test::validated_context;

namespace {

// Same frame on both backends: at most 0.5 % of pixels more than 8 levels apart in a channel
// (the GPU's float traversal may pick the neighbouring voxel where a ray grazes an edge), mean
// difference under 0.1 levels (what float vs double and exp vs a table leave: ~0.02).
void expect_images_close(const Image& gpu_image, const Image& cpu_image, const std::string& what) {
  ASSERT_EQ(gpu_image.width, cpu_image.width);
  ASSERT_EQ(gpu_image.height, cpu_image.height);
  const test::ImageDiff d = test::compare_images(gpu_image, cpu_image, 8);
  EXPECT_LE(d.off, d.pixels / 200)
      << what << ": " << d.off << " of " << d.pixels << " pixels differ by more than 8 levels";
  EXPECT_LT(d.mean, 0.1) << what;
}

}  // namespace

TEST(Gpu, RayMarchedFramesMatchTheCpuRenderer) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  World w = random_world({70, 50, 40}, 16, 0.004, 31);
  w.voxels.fill(Box3i{{0, 0, 0}, {70, 50, 3}}, 120);  // a floor to cast shadows on
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
    RenderSceneOptions so;
    so.skip_metric = m;
    const RenderScene scene(w, so);
    RenderOptions o;
    o.width = 160;
    o.height = 96;
    for (RenderView view : {RenderView::kShaded, RenderView::kChunks, RenderView::kDistance}) {
      o.view = view;
      for (const Camera& cam :
           {Camera::framing(scene.box(), 160.0 / 96), Camera::top(scene.box(), 160.0 / 96)}) {
        const std::string what = std::string(metric_name(m)) + " " + render_view_name(view);
        const gpu::Counters before = ctx->counters();
        const Image g = gpu::render(*ctx, scene, cam, o);
        EXPECT_EQ(ctx->counters().submits - before.submits, 1) << what;
        expect_images_close(g, render(scene, cam, o), what);
      }
    }
  }
  RenderOptions fog;
  fog.width = 96;
  fog.height = 64;
  fog.fog_density = 0.01;
  const RenderScene scene(w);
  const Camera cam = Camera::framing(scene.box(), 1.5);
  expect_images_close(gpu::render(*ctx, scene, cam, fog), render(scene, cam, fog), "fog");
  // Cameras placed in a world of non-cubic voxels: the GPU walks the same stretched rays.
  VoxelFrame scan;
  scan.voxel_size_world = {0.8, 1, 1.6};
  for (Camera placed : {cam, Camera::top(scene.box(), 1.5)}) {
    placed.eye = scan.world_from_vox(placed.eye);
    placed.target = scan.world_from_vox(placed.target);
    placed.up = scan.world_direction(placed.up);
    const Camera stretched = placed.in_voxels(scan);
    ASSERT_TRUE(stretched.world_frame.has_value());
    expect_images_close(gpu::render(*ctx, scene, stretched, fog), render(scene, stretched, fog),
                        "a camera in a frame of non-cubic voxels");
    RenderOptions chunks = fog;  // the grid lines' width from the stretched pixel footprint
    chunks.view = RenderView::kChunks;
    expect_images_close(gpu::render(*ctx, scene, stretched, chunks),
                        render(scene, stretched, chunks), "chunks, non-cubic voxels");
  }
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
  RenderOptions cut = fog;
  cut.view = RenderView::kDistance;
  for (int z : {3, 7, 39}) {  // just above the floor, a middle cut, the top layer
    cut.slice_z = z;
    expect_images_close(gpu::render(*ctx, scene, Camera::top(scene.box(), 1.5), cut),
                        render(scene, Camera::top(scene.box(), 1.5), cut),
                        "distance cut z=" + std::to_string(z));
  }
  cut.slice_z = 40;  // outside the box
  EXPECT_THROW(gpu::render(*ctx, scene, cam, cut), InvalidArgument);
  // The error view: the approximations' errors along each ray and the rays they let through
  // geometry (magenta), as the CPU draws them.
  RenderOptions error = fog;
  error.view = RenderView::kError;
  for (Algorithm alg : {Algorithm::kJfaSeed, Algorithm::kJfa, Algorithm::kExact}) {
    error.error_algorithm = alg;
    RenderStats cpu_stats;
    const Image cpu_image = render(scene, cam, error, &cpu_stats);
    // The approximation is computed on the device (its own submit, the algorithm's dispatches
    // beside the frame's one), then read back once into the frame's skip source.
    const gpu::Counters before = ctx->counters();
    expect_images_close(gpu::render(*ctx, scene, cam, error), cpu_image,
                        std::string("error view ") + algorithm_name(alg));
    const gpu::Counters after = ctx->counters();
    EXPECT_GE(after.submits - before.submits, 2) << algorithm_name(alg);
    EXPECT_GT(after.dispatches - before.dispatches, 2) << algorithm_name(alg);
    if (alg == Algorithm::kJfaSeed) {
      EXPECT_GT(cpu_stats.max_error, 0);  // the view has something to show
    }
  }
  // A SceneRenderer keeps the approximation while the scene and the algorithm stay: the next
  // error frame is its own submit alone.
  gpu::SceneRenderer renderer(ctx);
  renderer.sync(scene);
  error.error_algorithm = Algorithm::kJfa;
  (void)renderer.render(cam, error);
  const gpu::Counters kept = ctx->counters();
  expect_images_close(renderer.render(cam, error), render(scene, cam, error), "kept");
  EXPECT_EQ(ctx->counters().submits - kept.submits, 1);
}

TEST(Gpu, ResidentScenesFollowEditsWithOnlyTheirChunksCopied) {
  // A SceneRenderer synced after each batch of edits renders what a scene uploaded from scratch
  // renders (same GPU, same data: bit for bit), copies only the chunks that changed, and submits
  // nothing when nothing did.
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  World w = random_world({64, 48, 32}, 8, 0.003, 41);
  w.voxels.fill(Box3i{{0, 0, 0}, {64, 48, 4}}, 120);
  RenderSceneOptions so = DynamicRenderScene::default_options();
  so.skip_max_distance_vox = 10;
  so.lighting_max_distance_vox = 6;
  DynamicRenderScene live(w, so);
  gpu::SceneRenderer renderer(ctx);
  RenderOptions o;
  o.width = 96;
  o.height = 64;
  const Camera cam = Camera::framing(live.scene().box(), 1.5);
  EXPECT_TRUE(renderer.sync(live.scene()));
  gpu::Counters before = ctx->counters();
  EXPECT_FALSE(renderer.sync(live.scene()));
  EXPECT_EQ(ctx->counters().submits, before.submits);
  const std::int64_t chunk_bytes =
      8 * 8 * 8 * (2 + 1);  // skip cells (u16) + lighting (u8) per chunk
  std::mt19937 rng(8);
  auto uni = [&](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  DirtyRegions dirty(8, DirtyRegions::Track::kAnyChange);
  for (int batch = 0; batch < 6; ++batch) {
    for (int k = 0; k < 3; ++k) {
      const EditOp op = uni(0, 2) == 0 ? EditOp::kCarve
                        : uni(0, 1)    ? EditOp::kPlace
                                       : EditOp::kPaint;
      apply_edit(
          w,
          {op, SphereBrush{{uni(0, 63) * 1.0, uni(0, 47) * 1.0, uni(0, 20) * 1.0}, uni(1, 5) * 1.0},
           static_cast<std::uint8_t>(uni(1, 255))},
          &dirty);
    }
    const DynamicRenderScene::UpdateStats st = live.update(dirty);
    dirty.clear();
    before = ctx->counters();
    renderer.sync(live.scene());
    const gpu::Counters after = ctx->counters();
    EXPECT_LE(after.submits - before.submits, 1);
    EXPECT_EQ(after.bytes_downloaded, before.bytes_downloaded);
    // Each changed chunk: its cells, its chunk-table entry; plus the palette when it changed.
    EXPECT_LE(after.bytes_uploaded - before.bytes_uploaded,
              static_cast<std::int64_t>(st.chunks_changed) * (chunk_bytes + 16) + 256 * 16)
        << "batch " << batch;
    const Image incremental = renderer.render(cam, o);
    EXPECT_EQ(incremental.rgb, gpu::render(*ctx, live.scene(), cam, o).rgb) << "batch " << batch;
    const RenderScene fresh(w, live.skip_field(), live.light_field());
    EXPECT_EQ(incremental.rgb, gpu::render(*ctx, fresh, cam, o).rgb) << "batch " << batch;
    // The error view's approximation follows the edits: computed again for the edited scene.
    RenderOptions error = o;
    error.view = RenderView::kError;
    error.error_algorithm = Algorithm::kJfaSeed;
    EXPECT_EQ(renderer.render(cam, error).rgb, gpu::render(*ctx, fresh, cam, error).rgb)
        << "error view, batch " << batch;
  }
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size()
                                << " validation messages, first: " << messages.front();
  gpu::SceneRenderer unsynced(ctx);
  EXPECT_THROW(unsynced.render(cam, o), InvalidArgument);

  // Arenas outgrowing their device buffers: a nearly empty world where one edit makes dozens of
  // chunks dense. The buffers move on the GPU; still only the changed chunks travel.
  World sparse(8, Box3i::from_size({64, 64, 32}));
  sparse.voxels.set({5, 5, 5}, 3);
  DynamicRenderScene growing(sparse, so);
  gpu::SceneRenderer r2(ctx);
  r2.sync(growing.scene());
  for (int round = 0; round < 3; ++round) {
    DirtyRegions d(8, DirtyRegions::Track::kAnyChange);
    apply_edit(sparse,
               {EditOp::kPlace, SphereBrush{{12.0 + 20 * round, 30, 12}, 9 + 2.0 * round}, 40}, &d);
    const DynamicRenderScene::UpdateStats st = growing.update(d);
    before = ctx->counters();
    r2.sync(growing.scene());
    EXPECT_LE(ctx->counters().bytes_uploaded - before.bytes_uploaded,
              static_cast<std::int64_t>(st.chunks_changed) * (chunk_bytes + 16) + 256 * 16)
        << "round " << round;
    const RenderScene fresh(sparse, growing.skip_field(), growing.light_field());
    EXPECT_EQ(r2.render(cam, o).rgb, gpu::render(*ctx, fresh, cam, o).rgb) << "round " << round;
  }
  const auto late = ctx->validation_messages();
  EXPECT_TRUE(late.empty()) << late.size() << " validation messages, first: " << late.front();
}

// The render module's one API (render_executor.h) draws on the backend its executor names: on the
// CPU the CPU renderer's frames bit for bit, on the device the GPU renderer's, and a SceneView on a
// device follows an edit as a freshly uploaded scene does.
TEST(Gpu, TheExecutorApiDrawsOnTheChosenBackend) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  test::ExecutorScene s(random_world({40, 32, 24}, 8, 0.01, 5));
  const Camera& cam = s.camera();
  const RenderOptions& o = s.options();
  const Executor cpu = Executor::choose(Backend::kCpu), device(ctx);
  EXPECT_FALSE(cpu.on_gpu());
  EXPECT_EQ(device.backend(), Backend::kVulkan);
  EXPECT_EQ(render(cpu, s.scene(), cam, o).rgb, render(s.scene(), cam, o).rgb);
  EXPECT_EQ(render(device, s.scene(), cam, o).rgb, gpu::render(*ctx, s.scene(), cam, o).rgb);
  SceneView cpu_view(cpu), device_view(device);
  (void)device_view.render(s.scene(), cam, o);
  const RenderScene fresh = s.edit();
  EXPECT_EQ(cpu_view.render(s.scene(), cam, o).rgb, render(fresh, cam, o).rgb);
  EXPECT_EQ(device_view.render(s.scene(), cam, o).rgb, gpu::render(*ctx, fresh, cam, o).rgb);
  EXPECT_TRUE(ctx->validation_messages().empty());
}

// CSG models on Vulkan (gpu::render_csg): compiled variants, the interpreter and the mixed
// schedule give one image, which matches the CPU renderer's (same octree, camera and shading; the
// GPU marches in floats, so a ray grazing an edge may end a cell earlier or later: at most 1 % of
// pixels more than 8 levels apart, mean difference under 1 level).
TEST(Gpu, CsgFramesMatchTheCpuAndEveryEvaluatorAgrees) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  using E = gpu::CsgGpuOptions::Evaluators;
  // Under the sanitizers one model (every kernel still runs; glslang's compiles are what cost).
  const std::vector<const char*> models =
      testing_backends::kSanitizedBuild
          ? std::vector<const char*>{"gear.sdf"}
          : std::vector<const char*>{"gear.sdf", "blobs.sdf", "building.sdf"};
  for (const char* name : models) {
    const csg::Model model = test::csg_example(name);
    for (const auto view : {CsgRenderOptions::View::kShaded, CsgRenderOptions::View::kVariants}) {
      CsgRenderOptions o;
      o.width = 96;
      o.height = 72;
      o.depth = 5;
      o.view = view;
      const std::string what =
          std::string(name) + (view == CsgRenderOptions::View::kShaded ? " shaded" : " variants");
      const Image cpu = render_csg(model, o);
      gpu::CsgGpuStats compiled_stats, interpreted_stats;
      const Image compiled =
          gpu::render_csg(*ctx, model, o, nullptr, {E::kCompiled}, &compiled_stats);
      const Image interpreted =
          gpu::render_csg(*ctx, model, o, nullptr, {E::kInterpreter}, &interpreted_stats);
      // The compiled run left every variant's kernel in the context: a mixed frame after it
      // takes them all from there (no compile, no placeholder).
      gpu::CsgGpuStats mixed_stats;
      const Image mixed =
          gpu::render_csg(*ctx, model, o, nullptr, {E::kCompiledWhenReady}, &mixed_stats);
      EXPECT_EQ(mixed_stats.interpreted_dispatches, 0) << what;
      const test::ImageDiff d = test::compare_images(compiled, cpu, 8);
      EXPECT_LE(d.off, d.pixels / 100)
          << what << ": " << d.off << " of " << d.pixels << " pixels differ by more than 8 levels";
      EXPECT_LT(d.mean, 1.0) << what;
      EXPECT_EQ(test::compare_images(interpreted, compiled, 0).off, 0u) << what;
      EXPECT_EQ(test::compare_images(mixed, compiled, 0).off, 0u) << what;
      EXPECT_EQ(compiled_stats.interpreted_dispatches, 0) << what;
      EXPECT_EQ(interpreted_stats.compiled_dispatches, 0) << what;
      EXPECT_GT(compiled_stats.compiled_dispatches, 0) << what;
      EXPECT_EQ(compiled_stats.variants_compiled, compiled_stats.variants) << what;
    }
  }
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

// A variant needing more registers than the interpreter has: the interpreter alone refuses the
// model by name; the mixed schedule compiles that variant before the frame instead of drawing it
// with the interpreter, and gives the compiled image.
TEST(Gpu, CsgVariantsBeyondTheInterpreterAreCompiledFirst) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = validated_context();
  ctx->clear_validation_messages();
  // Right-nested unions keep every earlier sphere live while the rest are evaluated.
  std::string text;
  const int spheres = static_cast<int>(csg::kInterpreterRegisters) + 8;
  for (int i = 0; i < spheres; ++i)
    text +=
        "(union (move " + std::to_string(i % 9) + " " + std::to_string(i / 9) + " 0 (sphere 0.6)) ";
  text += "(sphere 0.1)" + std::string(static_cast<std::size_t>(spheres), ')');
  const csg::Model model = csg::parse_model(text, "nested.sdf");
  ASSERT_GT(csg::compile_tape(model).registers, csg::kInterpreterRegisters);
  CsgRenderOptions o;
  o.width = 40;
  o.height = 30;
  o.depth = 0;  // one cell: its variant is the whole tape
  using E = gpu::CsgGpuOptions::Evaluators;
  try {
    gpu::render_csg(*ctx, model, o, nullptr, {E::kInterpreter});
    ADD_FAILURE() << "the interpreter took a tape beyond its registers";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("registers"), std::string::npos) << e.what();
  }
  gpu::CsgGpuStats st;
  const Image mixed = gpu::render_csg(*ctx, model, o, nullptr, {E::kCompiledWhenReady}, &st);
  const Image compiled = gpu::render_csg(*ctx, model, o, nullptr, {E::kCompiled});
  EXPECT_EQ(test::compare_images(mixed, compiled, 0).off, 0u);
  EXPECT_EQ(st.interpreted_dispatches, 0);
  EXPECT_GT(test::compare_images(compiled, Image(40, 30), 0).off, 0u) << "an empty frame";
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}
