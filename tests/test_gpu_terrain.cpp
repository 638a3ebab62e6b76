// The GPU terrain renderer (gpu_terrain.h) against the CPU: its frame — marching cubes' classify
// and HistoPyramid, then one indirect draw whose vertex shader walks the pyramid — is compared
// with the CPU rasteriser's picture (render_mesh) of the CPU's marching-cubes mesh of the same
// terrain, from the same camera; its triangle count with the CPU mesh's; after edits, the rows it
// uploads with the changed box, and its frame with that of a renderer given the whole field
// afresh; the frame recorded into an application's command buffer with render()'s. Under the
// validation layer (synchronisation validation included).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

#include "gpu/recorder.h"
#include "gpu_suite.h"
#include "voxfield/gpu_mesh.h"
#include "voxfield/gpu_terrain.h"
#include "voxfield/gpu_terrain_vulkan.h"
#include "voxfield/mesh_render.h"

using namespace voxfield;

// A named namespace: unity builds put the GPU suites into one translation unit.
namespace gpu_terrain_test {

TerrainField hills(TerrainStorage storage, bool positive_inside, Vec3i samples = {49, 41, 29}) {
  TerrainOptions to;
  to.samples = samples;
  to.storage = storage;
  to.positive_inside = positive_inside;
  to.palette = default_palette();
  TerrainField t(to);
  const double sign = positive_inside ? -1 : 1;
  t.assign(
      [&](const Vec3d& p) { return sign * (p.z - 9 - 3 * std::sin(p.x / 5) * std::cos(p.y / 7)); },
      3);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 6; ++i) {
    TerrainBrush b;
    b.shape = i % 3 == 2 ? TerrainBrush::Shape::kBox : TerrainBrush::Shape::kSphere;
    b.mode = i % 2 ? TerrainBrush::Mode::kSubtract : TerrainBrush::Mode::kAdd;
    b.centre_units = {4 + u(rng) * (samples.x - 8), 4 + u(rng) * (samples.y - 8), 9 + 3 * u(rng)};
    b.radius_units = 3 + 3 * u(rng);
    b.half_extents_units = {3, 4, 2.5};
    b.smooth_units = i % 2 ? 0 : 1.5;
    b.material = static_cast<std::uint8_t>(20 + 40 * i);
    t.apply(b);
  }
  return t;
}

// Pixels whose channels differ by more than `tolerance` levels.
std::int64_t differing(const Image& a, const Image& b, int tolerance) {
  EXPECT_EQ(a.rgb.size(), b.rgb.size());
  std::int64_t n = 0;
  for (std::size_t i = 0; i + 2 < std::min(a.rgb.size(), b.rgb.size()); i += 3) {
    int worst = 0;
    for (int ch = 0; ch < 3; ++ch)
      worst = std::max(worst, std::abs(int{a.rgb[i + ch]} - int{b.rgb[i + ch]}));
    n += worst > tolerance;
  }
  return n;
}

std::int64_t covered(const Image& im, const MeshRenderOptions& o) {
  std::int64_t n = 0;
  for (std::size_t i = 0; i < im.rgb.size(); i += 3)
    n += !std::equal(o.background.begin(), o.background.end(),
                     im.rgb.begin() + static_cast<long>(i));
  return n;
}

// The GPU's frame and the CPU's picture of the CPU mesh agree on all but the pixels along
// triangle edges and silhouettes, where the two rasterisers' coverage rules differ (the CPU draws
// a pixel on an edge for both triangles, Vulkan for one; depth ties fall either way): at most
// 0.5 % of the pixels differ by more than 6 levels, and the covered areas within 1 % (on lavapipe
// no pixel differs by more than 6 levels here).
void expect_same_picture(const Image& gpu, const Image& cpu, const MeshRenderOptions& o) {
  const std::int64_t pixels = static_cast<std::int64_t>(o.width) * o.height;
  const std::int64_t cover_cpu = covered(cpu, o), cover_gpu = covered(gpu, o);
  ASSERT_GT(cover_cpu, pixels / 5) << "the terrain should fill a good part of the picture";
  EXPECT_LE(std::abs(cover_gpu - cover_cpu), cover_cpu / 100) << cover_gpu << " vs " << cover_cpu;
  EXPECT_LE(differing(gpu, cpu, 6), pixels * 5 / 1000);
}

TEST(GpuTerrain, FramesMatchTheCpuRasteriserOfTheCpuMesh) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  MeshRenderOptions o;
  o.width = 200;
  o.height = 150;
  for (TerrainStorage storage : {TerrainStorage::kI8, TerrainStorage::kI16, TerrainStorage::kF32})
    for (gpu::Pyramid pyramid : {gpu::Pyramid::kFourToOne, gpu::Pyramid::kEightToOne}) {
      const bool positive_inside = storage == TerrainStorage::kI16;
      SCOPED_TRACE(std::string(terrain_storage_name(storage)) +
                   (pyramid == gpu::Pyramid::kFourToOne ? " 4-to-1" : " 8-to-1"));
      const TerrainField t = hills(storage, positive_inside);
      const Mesh mesh = mesh_terrain(t, MeshOptions{});
      ASSERT_GT(mesh.triangle_count(), 2000u);
      gpu::TerrainRenderer r(ctx, pyramid);
      r.sync(t);
      const Box3i box = Box3i::from_size(t.size());
      for (const Camera& camera : {Camera::framing(box, 4.0 / 3), Camera::top(box, 4.0 / 3)}) {
        gpu::TerrainDrawStats st;
        const Image gpu_frame = r.render(terrain_view(camera, o), &st);
        const Image cpu_frame = render_mesh(mesh, camera, o);
        expect_same_picture(gpu_frame, cpu_frame, o);
        EXPECT_EQ(st.triangles, mesh.triangle_count());
        EXPECT_EQ(r.last_triangles(), mesh.triangle_count());
        // One submit: classify, a reduction per level, the arguments; one draw; only the pixels
        // come back.
        EXPECT_EQ(st.submits, 1);
        EXPECT_EQ(st.draws, 1);
        EXPECT_EQ(st.dispatches, 1 + (st.pyramid_levels - 1) + 1);
        EXPECT_EQ(st.bytes_downloaded, 4 * o.width * o.height);
        if (!st.passes.empty()) {  // the queue has timestamps: classify, HistoPyramid, draw
          ASSERT_EQ(st.passes.size(), 3u);
          EXPECT_EQ(st.passes[2].pass, "draw");
        }
      }
      // Without colours: the base colour, as the CPU draws it.
      MeshRenderOptions plain = o;
      plain.use_colors = false;
      const Camera camera = Camera::framing(box, 4.0 / 3);
      expect_same_picture(r.render(terrain_view(camera, plain)), render_mesh(mesh, camera, plain),
                          plain);
      voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
    }
}

TEST(GpuTerrain, EditsUploadTheirRowsAndDrawAsAFreshCopy) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  MeshRenderOptions o;
  o.width = 160;
  o.height = 120;
  for (TerrainStorage storage : {TerrainStorage::kI8, TerrainStorage::kF32}) {
    SCOPED_TRACE(terrain_storage_name(storage));
    TerrainField t = hills(storage, false);
    gpu::TerrainRenderer kept(ctx);
    const std::uint64_t whole = kept.sync(t);
    const Camera camera = Camera::framing(Box3i::from_size(t.size()), 4.0 / 3);
    const int width = storage == TerrainStorage::kI8 ? 1 : 4;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 5; ++i) {
      TerrainBrush b;
      b.mode = i % 2 ? TerrainBrush::Mode::kSubtract : TerrainBrush::Mode::kAdd;
      b.centre_units = {8 + 30 * u(rng), 8 + 25 * u(rng), 10};
      b.radius_units = 2.5;
      b.material = static_cast<std::uint8_t>(100 + i);
      const Box3i changed = t.apply(b);
      ASSERT_FALSE(changed.empty());
      const std::uint64_t sent = kept.sync(t, changed);
      // The box's samples and materials, in the field's width: far less than the whole field.
      EXPECT_EQ(sent, static_cast<std::uint64_t>(changed.volume()) * (width + 1));
      EXPECT_LT(sent * 8, whole);
    }
    EXPECT_EQ(kept.sync(t, Box3i{}), 0u);
    gpu::TerrainRenderer fresh(ctx);
    fresh.sync(t);
    const gpu::TerrainView view = terrain_view(camera, o);
    const Image a = kept.render(view), b = fresh.render(view);
    EXPECT_EQ(a.rgb, b.rgb) << "the edited copy draws otherwise than a fresh one";
    const Mesh mesh = mesh_terrain(t, MeshOptions{});
    EXPECT_EQ(kept.last_triangles(), mesh.triangle_count());
    expect_same_picture(a, render_mesh(mesh, camera, o), o);
    voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
  }
}

TEST(GpuTerrain, RecordedIntoAnApplicationsCommandBuffer) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  gpu::Context::Impl& c = ctx->impl();
  const TerrainField t = hills(TerrainStorage::kI16, false);
  gpu::TerrainRenderer r(ctx);
  r.sync(t);
  MeshRenderOptions o;
  o.width = 96;
  o.height = 64;
  const gpu::TerrainView view = terrain_view(Camera::framing(Box3i::from_size(t.size()), 1.5), o);
  const Image want = r.render(view);
  for (gpu::PixelOrder order : {gpu::PixelOrder::kBgra, gpu::PixelOrder::kRgba}) {
    const VkDeviceSize bytes = 4ull * o.width * o.height;
    gpu::Buffer host(c, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
    // Two frames in one command buffer, as an application drawing twice would; the second reads
    // what the first's copy left alone.
    test::run_commands(c, [&](VkCommandBuffer cmd) {
      for (int frame = 0; frame < 2; ++frame) {
        const VkBuffer px = gpu::record_render(r, cmd, view, order);
        if (frame == 0) continue;
        const VkBufferCopy region{0, 0, bytes};
        vkCmdCopyBuffer(cmd, px, host.handle(), 1, &region);
        VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                             &to_host, 0, nullptr, 0, nullptr);
      }
    });
    const auto* px = static_cast<const std::uint8_t*>(host.mapped());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < want.rgb.size() / 3; ++i) {
      const std::uint8_t* p = px + 4 * i;
      const std::uint8_t rgb[3] = {order == gpu::PixelOrder::kBgra ? p[2] : p[0], p[1],
                                   order == gpu::PixelOrder::kBgra ? p[0] : p[2]};
      differ += std::memcmp(rgb, &want.rgb[3 * i], 3) != 0 || p[3] != 255;
    }
    EXPECT_EQ(differ, 0u);
    EXPECT_EQ(r.last_triangles(), mesh_terrain(t, MeshOptions{}).triangle_count());
  }
  voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

// Every pass strides over its work (dispatch_strided) rather than splitting it over y: with the
// device's workgroup limit along x cut to 3 for the test — so classify, the pyramid's lower levels
// and the traversal each run past the limit — marching cubes still gives the CPU's triangles and
// the terrain renderer the same frame as with the real limit.
TEST(GpuTerrain, PassesStridePastTheWorkgroupLimit) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  const TerrainField t = hills(TerrainStorage::kI16, false, {40, 36, 24});
  MeshRenderOptions o;
  o.width = 80;
  o.height = 60;
  const gpu::TerrainView view =
      terrain_view(Camera::framing(Box3i::from_size(t.size()), 4.0 / 3), o);
  gpu::TerrainRenderer normal(ctx);
  normal.sync(t);
  const Image want = normal.render(view);
  std::uint32_t& limit = ctx->impl().limits.maxComputeWorkGroupCount[0];
  const std::uint32_t saved = limit;
  struct Restore {
    std::uint32_t& limit;
    std::uint32_t saved;
    ~Restore() { limit = saved; }
  } restore{limit, saved};
  limit = 3;  // 192 invocations a dispatch: the 35 x 39 x 23 cells need 164 strides
  {
    gpu::TerrainRenderer strided(ctx);
    strided.sync(t);
    EXPECT_EQ(strided.render(view).rgb, want.rgb);
    EXPECT_EQ(strided.last_triangles(), mesh_terrain(t, MeshOptions{}).triangle_count());
    gpu::GpuMeshStats st;
    const Mesh got = gpu::marching_cubes(*ctx, t, {}, &st);
    const Mesh cpu = mesh_terrain(t, MeshOptions{});
    EXPECT_EQ(got.triangle_count(), cpu.triangle_count());
    EXPECT_EQ(got.vertex_count(), cpu.vertex_count());
    // (Summed in the pyramid's triangle order, not the CPU's: equal to rounding.)
    EXPECT_NEAR(mesh_stats(got).signed_volume_units3, mesh_stats(cpu).signed_volume_units3,
                1e-9 * mesh_stats(cpu).signed_volume_units3);
    ASSERT_GT(st.triangles, 3u * 64);  // the traversal strode too
  }
  voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

TEST(GpuTerrain, BadRequests) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  EXPECT_THROW(gpu::TerrainRenderer(nullptr), InvalidArgument);
  gpu::TerrainRenderer r(ctx);
  gpu::TerrainView view;
  view.width = 32;
  view.height = 32;
  EXPECT_THROW(r.render(view), InvalidArgument);  // nothing synced
  TerrainField t = hills(TerrainStorage::kI8, false, {20, 18, 16});
  EXPECT_THROW(r.sync(t, Box3i{{0, 0, 0}, {21, 1, 1}}), InvalidArgument);
  r.sync(t);
  view.width = 0;
  EXPECT_THROW(r.render(view), InvalidArgument);
  view.width = 32;
  view.scale = 0;
  EXPECT_THROW(r.render(view), InvalidArgument);
  MeshRenderOptions edges;
  edges.edges = true;
  EXPECT_THROW(terrain_view(Camera{}, edges), InvalidArgument);
  // A terrain of another size is copied whole, whatever box is given.
  const TerrainField other = hills(TerrainStorage::kI8, false, {24, 18, 16});
  EXPECT_GT(r.sync(other, Box3i{{0, 0, 0}, {1, 1, 1}}), 24u * 18 * 16);
  view.scale = 1;
  view.eye = {12, -30, 20};
  view.forward = Vec3d{0, 1, -0.5}.normalized();
  view.right = {1, 0, 0};
  view.up = cross(view.right, view.forward);
  const Image im = r.render(view);
  EXPECT_EQ(im.width, 32);
  EXPECT_EQ(r.last_triangles(), mesh_terrain(other, MeshOptions{}).triangle_count());
  voxfield::testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

}  // namespace gpu_terrain_test
