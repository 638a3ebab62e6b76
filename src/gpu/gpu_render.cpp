// voxfield GPU backend — frames from the ray-marching compute shader (shaders/render.comp).
//
// The scene's bricked arenas (src/render/scene_impl.h: distance + material cells, the lighting
// field, per-chunk flags) are uploaded as they are, so the shader walks exactly the data the CPU
// walks. Upload, one dispatch and the read-back of the image: one command buffer, one submit.
#include <chrono>
#include <cstring>

#include "../../shaders/layout.h"
#include "../render/scene_impl.h"
#include "vulkan_context.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

struct Upload {
  std::vector<std::uint8_t> bytes;
  VkDeviceSize add(const void* data, std::size_t n) {
    const VkDeviceSize offset = (bytes.size() + 15) / 16 * 16;
    bytes.resize(offset + std::max<std::size_t>(n, 4));
    if (n > 0) std::memcpy(bytes.data() + offset, data, n);
    return offset;
  }
};

L::vec4f v4(const Vec3d& v, double w = 0) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z), static_cast<float>(w)};
}

}  // namespace

Image render(Context& context, const RenderScene& scene, const Camera& camera, const RenderOptions& o,
             RenderStats* stats, std::vector<PassTiming>* timings) {
  Context::Impl& ctx = context.impl();
  const RenderScene::Impl& s = scene.impl();
  if (o.view != RenderView::kShaded && o.view != RenderView::kChunks)
    throw InvalidArgument(std::string("GPU: the ") + render_view_name(o.view) +
                          " view is not on the Vulkan backend yet (shaded and chunks are)");
  if (o.skip != SkipMode::kDistance) throw InvalidArgument("GPU: the Vulkan ray marcher always skips by distance");
  if (o.width <= 0 || o.height <= 0 || o.width > 16384 || o.height > 16384)
    throw InvalidArgument("render: image size out of range (1..16384 per side)");
  if ((o.ambient_occlusion || o.soft_shadows) && !s.has_light)
    throw InvalidArgument("render: ambient occlusion and soft shadows need the scene's lighting field");
  if (!(o.sun_direction.length() > 0)) throw InvalidArgument("render: the sun direction must be non-zero");

  const Camera::Projector pj = camera.projector(o.width, o.height);
  L::RenderParams rp{};
  rp.eye = v4(pj.eye, pj.projection == Camera::Projection::kOrthographic ? 1 : 0);
  rp.forward = v4(pj.forward);
  rp.right = v4(pj.right);
  rp.up = v4(pj.up);
  rp.sun = v4(o.sun_direction.normalized(), o.fog_density);
  rp.box_begin = {s.box.begin.x, s.box.begin.y, s.box.begin.z, 0};
  rp.box_end = {s.box.end.x, s.box.end.y, s.box.end.z, 0};
  const Vec3i first = s.table.first_chunk(), dims = s.table.chunk_dims();
  rp.first_chunk = {first.x, first.y, first.z, s.table.shift()};
  rp.chunk_dims = {dims.x, dims.y, dims.z, static_cast<std::int32_t>(s.skip.cells.chunk_volume)};
  rp.width = static_cast<std::uint32_t>(o.width);
  rp.height = static_cast<std::uint32_t>(o.height);
  rp.scale = static_cast<float>(pj.scale);
  rp.metric = static_cast<std::uint32_t>(s.skip.metric);
  rp.skip_inv_scale = static_cast<float>(s.skip.inv_scale);
  rp.light_inv_scale = static_cast<float>(s.light_inv_scale);
  rp.flags = (o.ambient_occlusion ? 1u : 0u) | (o.soft_shadows ? 2u : 0u) | (o.view == RenderView::kChunks ? 4u : 0u) |
             (s.has_light ? 8u : 0u);

  const std::size_t chunks = s.table.chunk_count();
  std::vector<std::uint32_t> info(4 * chunks);
  for (std::size_t i = 0; i < chunks; ++i) {
    info[4 * i] = s.skip.cells.slot[i] == BrickedChunks<std::uint16_t>::kUniform ? L::VF_UNIFORM : s.skip.cells.slot[i];
    info[4 * i + 1] = static_cast<std::uint32_t>(s.skip.cells.uniform[i]) | (std::uint32_t{s.skip.chunk_min[i]} << 16) |
                      (s.empty_chunk[i] ? 1u << 24 : 0u) | (s.dense_material[i] ? 1u << 25 : 0u);
    if (s.has_light) {
      info[4 * i + 2] = s.light.slot[i] == BrickedChunks<std::uint8_t>::kUniform ? L::VF_UNIFORM : s.light.slot[i];
      info[4 * i + 3] = s.light.uniform[i];
    } else {
      info[4 * i + 2] = L::VF_UNIFORM;
      info[4 * i + 3] = 0;
    }
  }
  std::vector<float> palette(256 * 4);
  for (int m = 0; m < 256; ++m)
    for (int c = 0; c < 3; ++c) palette[static_cast<std::size_t>(4 * m + c)] = s.albedo[static_cast<std::size_t>(m)][static_cast<std::size_t>(c)];

  Upload up;
  const std::size_t sizes[5] = {sizeof rp, info.size() * 4, s.skip.cells.arena.size(), s.has_light ? s.light.arena.size() : 0,
                                palette.size() * 4};
  const void* sources[5] = {&rp, info.data(), s.skip.cells.arena.data(), s.has_light ? s.light.arena.data() : nullptr,
                            palette.data()};
  VkDeviceSize offsets[5];
  for (int b = 0; b < 5; ++b) offsets[b] = up.add(sources[b], sizes[b]);
  const VkDeviceSize image_bytes = static_cast<VkDeviceSize>(o.width) * o.height * 4;

  constexpr VkBufferUsageFlags kUsage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  Buffer buffers[6];
  for (int b = 0; b < 5; ++b) buffers[b] = Buffer(ctx, std::max<std::size_t>(sizes[b], 4), kUsage, false);
  buffers[5] = Buffer(ctx, image_bytes, kUsage, false);
  Buffer& upload = ctx.upload_buffer(up.bytes.size());
  std::memcpy(upload.mapped(), up.bytes.data(), up.bytes.size());
  Buffer& readback = ctx.readback_buffer(image_bytes);

  const Buffer* bound[Context::Impl::kRenderBindings] = {&buffers[0], &buffers[1], &buffers[2],
                                                         &buffers[3], &buffers[4], &buffers[5]};
  const VkDescriptorSet set = ctx.bind(ctx.render_layout, bound);

  const bool timed = timings && ctx.timestamps != VK_NULL_HANDLE;
  const auto t0 = std::chrono::steady_clock::now();
  ctx.run_commands([&](VkCommandBuffer cmd) {
    if (timed) vkCmdResetQueryPool(cmd, ctx.timestamps, 0, 2);
    for (int b = 0; b < 5; ++b) {
      const VkBufferCopy copy{offsets[b], 0, std::max<std::size_t>(sizes[b], 4)};
      vkCmdCopyBuffer(cmd, upload.handle(), buffers[b].handle(), 1, &copy);
      ctx.counters.bytes_uploaded += static_cast<std::int64_t>(sizes[b]);
    }
    barrier(ctx, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
            VK_ACCESS_SHADER_READ_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx.render.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx.render_layout.pipeline, 0, 1, &set, 0, nullptr);
    if (timed) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, ctx.timestamps, 0);
    dispatch(ctx, cmd, static_cast<std::uint64_t>(o.width) * o.height);
    if (timed) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, ctx.timestamps, 1);
    barrier(ctx, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_ACCESS_TRANSFER_READ_BIT);
    const VkBufferCopy down{0, 0, image_bytes};
    vkCmdCopyBuffer(cmd, buffers[5].handle(), readback.handle(), 1, &down);
    barrier(ctx, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
            VK_ACCESS_HOST_READ_BIT);
    ctx.counters.bytes_downloaded += static_cast<std::int64_t>(image_bytes);
  });
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (timings) {
    timings->clear();
    if (timed) {
      std::uint64_t ticks[2];
      check(vkGetQueryPoolResults(ctx.device, ctx.timestamps, 0, 2, sizeof ticks, ticks, 8,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
      timings->push_back({"render", static_cast<double>(ticks[1] - ticks[0]) * ctx.timestamp_period_ns * 1e-6});
    }
  }

  Image image(o.width, o.height);
  const auto* px = static_cast<const std::uint32_t*>(readback.mapped());
  for (std::size_t i = 0; i < static_cast<std::size_t>(o.width) * o.height; ++i) {
    image.rgb[3 * i] = static_cast<std::uint8_t>(px[i] & 0xFF);
    image.rgb[3 * i + 1] = static_cast<std::uint8_t>((px[i] >> 8) & 0xFF);
    image.rgb[3 * i + 2] = static_cast<std::uint8_t>((px[i] >> 16) & 0xFF);
  }
  if (stats) {
    *stats = RenderStats{};
    stats->ms = ms;  // upload + render + read-back, as the caller waits for it
    stats->width = o.width;
    stats->height = o.height;
    stats->primary.rays = static_cast<std::int64_t>(o.width) * o.height;
  }
  return image;
}

}  // namespace voxfield::gpu
