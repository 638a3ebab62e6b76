// The vector-field passes on Vulkan (gpu_vectors.h) against the CPU half: every algorithm, rule and
// storage gives the CPU's texels and winners bit for bit on lavapipe (whose division and square
// root are correctly rounded — the condition gpu_vectors.h states); a simulation's steps give the
// CPU simulation's fields; the visualiser matches the CPU's image within a stated tolerance; each
// step is one submission; oversized textures are refused. Lavapipe under the validation layer.
#include <gtest/gtest.h>

#include <cstring>
#include <functional>

#include "gpu/vulkan_context.h"
#include "gpu_suite.h"
#include "vector_test_inputs.h"
#include "voxfield/gpu_vectors_vulkan.h"

using namespace voxfield;

// A named namespace: unity builds put the GPU suites into one translation unit.
namespace vector_passes_test {

const VectorAlgorithm kAlgorithms[] = {VectorAlgorithm::kBrute, VectorAlgorithm::kSplat,
                                       VectorAlgorithm::kJfa, VectorAlgorithm::kJfaPlus1,
                                       VectorAlgorithm::kJfaPlus2};
const VectorStorage kStorages[] = {VectorStorage::kRgba8, VectorStorage::kRgba16f,
                                   VectorStorage::kRgba32f};

// The index of the first differing byte, or -1.
std::ptrdiff_t first_difference(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) {
  if (a.size() != b.size()) return 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i] != b[i]) return static_cast<std::ptrdiff_t>(i);
  return -1;
}

TEST(GpuVectorPasses, GenerationsEqualTheCpuBitForBit) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  for (const test::Shape& shape : test::shapes()) {
    const std::vector<VectorSource> sources = test::random_sources(shape.volume, 30, 19);
    for (VectorAlgorithm algorithm : kAlgorithms)
      for (VectorRule rule : {VectorRule::kStrongest, VectorRule::kNearest})
        for (VectorStorage storage : kStorages) {
          SCOPED_TRACE(std::string(shape.name) + " " + vector_algorithm_name(algorithm) + " " +
                       vector_rule_name(rule) + " " + vector_storage_name(storage));
          VectorOptions o;
          o.algorithm = algorithm;
          o.rule = rule;
          const std::vector<std::int32_t> cpu_winners = vector_winners(shape.volume, sources, o);
          const VectorTexture cpu = generate_vectors(shape.volume, sources, storage, o);
          std::vector<std::int32_t> gpu_winners;
          gpu::VectorGpuStats stats;
          const VectorTexture gpu =
              gpu::generate_vectors(*ctx, shape.volume, sources, storage, o, &gpu_winners, &stats);
          ASSERT_EQ(gpu_winners, cpu_winners);
          EXPECT_EQ(first_difference(gpu.bytes(), cpu.bytes()), -1);
          // brute / splat: one dispatch; jump flooding: seeding, the passes, the conversion.
          const bool jfa =
              algorithm != VectorAlgorithm::kBrute && algorithm != VectorAlgorithm::kSplat;
          EXPECT_EQ(stats.dispatches, jfa ? 2 + stats.flood_passes : 1);
          if (algorithm == VectorAlgorithm::kSplat) {
            EXPECT_GT(stats.tile_entries, 0);
          }
        }
  }
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

TEST(GpuVectorPasses, NoSourcesAndSourcesOutsideGiveTheZeroTexture) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  const VectorVolume v = test::cube_volume(12);
  VectorSource far;
  far.position = far.previous = {100, 0, 0};
  far.radius = 2;
  for (VectorAlgorithm algorithm : kAlgorithms) {
    VectorOptions o;
    o.algorithm = algorithm;
    for (std::span<const VectorSource> s :
         {std::span<const VectorSource>(), std::span<const VectorSource>(&far, 1)}) {
      const VectorTexture gpu = gpu::generate_vectors(*ctx, v, s, VectorStorage::kRgba8, o);
      EXPECT_EQ(
          first_difference(gpu.bytes(), VectorTexture(v.resolution, VectorStorage::kRgba8).bytes()),
          -1)
          << vector_algorithm_name(algorithm);
    }
  }
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

// Frames of moving sources (some frames without any), decayed and blended: the device's field
// equals the CPU simulation's after every step, in every storage, for splatting and jump flooding.
TEST(GpuVectorPasses, StepsEqualTheCpuSimulation) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  const VectorVolume v = test::shapes()[2].volume;  // rotated, anisotropic
  for (VectorAlgorithm algorithm : {VectorAlgorithm::kSplat, VectorAlgorithm::kJfa})
    for (VectorStorage storage : kStorages) {
      SCOPED_TRACE(std::string(vector_algorithm_name(algorithm)) + " " +
                   vector_storage_name(storage));
      VectorOptions o;
      o.algorithm = algorithm;
      voxfield::VectorSimulation cpu(v, storage, o, 2.5);
      gpu::VectorSimulation gpu(ctx, v, storage, o, 2.5);
      for (int step = 0; step < 8; ++step) {
        const std::vector<VectorSource> sources =
            test::random_sources(v, step % 4 == 3 ? 0 : 8, 60 + step);
        const double dt = 1.0 / 60 + 0.004 * step;
        cpu.step(sources, dt);
        gpu.step(sources, dt);
        ASSERT_EQ(first_difference(gpu.field().bytes(), cpu.field().bytes()), -1)
            << "after step " << step;
        ASSERT_EQ(first_difference(gpu.current().bytes(), cpu.current().bytes()), -1)
            << "after step " << step;
        // One submission and one fence wait per step, read-backs aside.
        EXPECT_EQ(gpu.last_stats().submits, 1);
        EXPECT_EQ(gpu.last_stats().fence_waits, 1);
        EXPECT_EQ(gpu.last_stats().bytes_downloaded, 0);
      }
      EXPECT_EQ(gpu.steps(), 8);
    }
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

// The visualiser works in floats (the CPU's in doubles): nearly every pixel within 1 of 255 per
// channel (measured: all of them), none off by more than 16 (a ray grazing an edge of the box or
// the sheet, or a sample straddling a texel boundary, may take one more or one fewer step), and the
// picture not the background alone; with the reactive sheet as well.
TEST(GpuVectorPasses, TheVisualiserMatchesTheCpuImage) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  const VectorVolume v = test::shapes()[2].volume;
  const std::vector<VectorSource> sources = test::random_sources(v, 20, 4);
  for (VectorStorage storage : kStorages)
    for (bool sheet : {false, true}) {
      SCOPED_TRACE(std::string(vector_storage_name(storage)) + (sheet ? " with the sheet" : ""));
      const VectorTexture tex = generate_vectors(v, sources, storage);
      VectorViewOptions view;
      view.width = 96;
      view.height = 64;
      view.sheet = sheet;
      view.sheet_push = 1.5;
      const Image cpu = render_vectors(v, tex, view);
      gpu::VectorGpuStats stats;
      const Image gpu = gpu::render_vectors(*ctx, v, tex, view, &stats);
      const Image empty = render_vectors(v, VectorTexture(v.resolution, storage), view);
      int close = 0, lit = 0, worst = 0;
      for (int y = 0; y < view.height; ++y)
        for (int x = 0; x < view.width; ++x) {
          int off = 0;
          for (int c = 0; c < 3; ++c)
            off = std::max(off, std::abs(int{gpu.pixel(x, y)[c]} - int{cpu.pixel(x, y)[c]}));
          worst = std::max(worst, off);
          close += off <= 1;
          lit += cpu.pixel(x, y)[0] != empty.pixel(x, y)[0];
        }
      EXPECT_GT(lit, view.width * view.height / 20);
      EXPECT_GE(close, view.width * view.height * 99 / 100);
      EXPECT_LE(worst, 16);
      EXPECT_EQ(stats.dispatches, 1);
      if (sheet) {  // the sheet is in the picture
        VectorViewOptions without = view;
        without.sheet = false;
        const Image bare = render_vectors(v, tex, without);
        int covered = 0;
        for (int y = 0; y < view.height; ++y)
          for (int x = 0; x < view.width; ++x)
            covered += std::memcmp(bare.pixel(x, y), cpu.pixel(x, y), 3) != 0;
        EXPECT_GT(covered, view.width * view.height / 10);
      }
    }
  // The simulation draws its resident field the same way.
  gpu::VectorSimulation sim(ctx, v, VectorStorage::kRgba8, {}, 1.0);
  sim.step(sources, 0.02);
  VectorViewOptions view;
  view.width = 48;
  view.height = 32;
  const Image a = sim.render(view), b = gpu::render_vectors(*ctx, v, sim.field(), view);
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x) ASSERT_EQ(std::memcmp(a.pixel(x, y), b.pixel(x, y), 3), 0);
  testing_backends::expect_no_validation_messages(Backend::kVulkan);

  // On a device whose storage-buffer range is below the image (lowered through ContextOptions,
  // as a user sharing a device would), the image is written through four windows
  // (src/gpu/split_buffer.h): the same pixels. An image past four windows is refused by name.
  auto small = test::capped_context(32 * 1024 - 4);  // windows of 16 KiB
  const VectorTexture rgba = generate_vectors(v, sources, VectorStorage::kRgba8);  // 20 KiB
  VectorViewOptions wide;
  wide.width = 160;  // 51 200 bytes of pixels: four windows
  wide.height = 80;
  wide.sheet = true;
  EXPECT_EQ(gpu::render_vectors(*small, v, rgba, wide).rgb,
            gpu::render_vectors(*ctx, v, rgba, wide).rgb);
  wide.width = 256;  // 81 920 bytes
  try {
    (void)gpu::render_vectors(*small, v, rgba, wide);
    ADD_FAILURE() << "an image past four windows was drawn";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("more than this device binds"), std::string::npos)
        << e.what();
  }
  test::expect_no_validation_messages(*small);
}

// Steps and pictures recorded into a command buffer the application owns and submits: the same
// fields as the simulation's own steps, and the visualiser's pixels in either byte order.
TEST(GpuVectorPasses, StepsRecordedIntoTheApplicationsCommandBuffer) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  gpu::Context::Impl& c = ctx->impl();
  const VectorVolume v = test::shapes()[2].volume;
  gpu::VectorSimulation own(ctx, v, VectorStorage::kRgba8, {}, 2.0);
  gpu::VectorSimulation app(ctx, v, VectorStorage::kRgba8, {}, 2.0);
  VectorViewOptions view;
  view.width = 40;
  view.height = 30;
  view.sheet = true;
  for (int step = 0; step < 4; ++step) {
    const std::vector<VectorSource> sources = test::random_sources(v, 6, 90 + step);
    own.step(sources, 0.05);
    gpu::VectorFieldBuffer field;
    VkBuffer pixels = VK_NULL_HANDLE;
    const gpu::PixelOrder order = step % 2 ? gpu::PixelOrder::kBgra : gpu::PixelOrder::kRgba;
    view.width = 40 + 16 * step;  // a growing picture replaces the pixel buffer after the step
    const VkDeviceSize bytes = static_cast<VkDeviceSize>(view.width) * view.height * 4;
    gpu::Buffer readback(c, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
    test::run_commands(c, [&](VkCommandBuffer cmd) {
      field = gpu::record_step(app, cmd, sources, 0.05);
      pixels = gpu::record_render(app, cmd, view, order);
      // The application's copy of the picture (record_render made it readable by transfers).
      const VkBufferCopy region{0, 0, bytes};
      vkCmdCopyBuffer(cmd, pixels, readback.handle(), 1, &region);
      VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      to_host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
      to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1,
                           &to_host, 0, nullptr, 0, nullptr);
    });
    // The same picture as the simulation draws on its own, in the byte order asked for.
    const Image want = app.render(view);
    const auto* got = static_cast<const std::uint8_t*>(readback.mapped());
    int differ = 0;
    for (int y = 0; y < view.height; ++y)
      for (int x = 0; x < view.width; ++x) {
        const std::uint8_t* g = got + 4 * (static_cast<std::size_t>(y) * view.width + x);
        const std::uint8_t* w = want.pixel(x, y);
        const bool bgra = order == gpu::PixelOrder::kBgra;
        differ += g[bgra ? 2 : 0] != w[0] || g[1] != w[1] || g[bgra ? 0 : 2] != w[2] || g[3] != 255;
      }
    EXPECT_EQ(differ, 0) << "step " << step;
    EXPECT_EQ(field.buffer, gpu::field_buffer(app).buffer);
    EXPECT_EQ(field.bytes, static_cast<VkDeviceSize>(v.voxel_count()) * 4);
    ASSERT_EQ(first_difference(app.field().bytes(), own.field().bytes()), -1) << "step " << step;
    ASSERT_NE(pixels, VkBuffer{VK_NULL_HANDLE});
  }
  EXPECT_EQ(app.steps(), 4);
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

TEST(GpuVectorPasses, RefusesWhatTheDeviceCannotHoldAndBadInput) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  VectorVolume huge = test::cube_volume(16);
  huge.resolution = {2048, 2048, 8};  // 32 M texels: 512 MiB of rgba32f, past lavapipe's 128 MiB
  try {
    gpu::VectorSimulation sim(ctx, huge, VectorStorage::kRgba32f, {}, 1.0);
    ADD_FAILURE() << "an oversized texture was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("storage buffer"), std::string::npos) << e.what();
  }
  const VectorVolume v = test::cube_volume(8);
  gpu::VectorSimulation sim(ctx, v, VectorStorage::kRgba8, {}, 1.0);
  VectorSource bad;
  bad.position = bad.previous = {0, 0, 0};
  bad.radius = -1;
  EXPECT_THROW(sim.step(std::span(&bad, 1), 0.1), InvalidArgument);
  EXPECT_THROW(sim.step({}, 0), InvalidArgument);
  EXPECT_EQ(sim.steps(), 0);
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

// Past the device's x limit of workgroups (lavapipe: 65535 x 64 voxels): the passes stride over
// the rest (dispatches split over y lost their second row on lavapipe).
TEST(GpuVectorPasses, VolumesPastOneDispatchRow) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  VectorVolume vol;
  vol.size = {10, 10, 10};
  vol.resolution = {176, 176, 176};
  std::vector<VectorSource> sources;
  for (int i = 0; i < 20; ++i) {
    VectorSource s;
    s.position = {-4 + 0.4 * i, (i % 5) - 2.0, 4.0 - 0.4 * i};
    s.previous = s.position;
    s.radius = 1.5;
    sources.push_back(s);
  }
  for (VectorAlgorithm a : {VectorAlgorithm::kBrute, VectorAlgorithm::kSplat}) {
    VectorOptions o;
    o.algorithm = a;
    const VectorTexture cpu = generate_vectors(vol, sources, VectorStorage::kRgba8, o);
    const VectorTexture gpu = gpu::generate_vectors(*ctx, vol, sources, VectorStorage::kRgba8, o);
    EXPECT_EQ(first_difference(cpu.bytes(), gpu.bytes()), -1) << vector_algorithm_name(a);
  }
}

}  // namespace vector_passes_test
