// voxfield GPU backend — the exact distance transform on Vulkan compute.
//
// The same separable algorithm as the CPU (Meijster, Roerdink & Hesselink 2000), as three kinds of
// dispatch: edt_sites (distances along x to the nearest site), edt_lines (the lower envelope along
// y, then z) and edt_encode (stored values, encoded exactly like the CPU's). Each pass reads what
// the previous one wrote across the whole domain, so passes are separate dispatches with a
// pipeline barrier between them — barrier() in GLSL only orders one workgroup, which is how the
// dissertation's single-shader version raced. Everything — upload, every pass, read-back — is in
// one command buffer: one submit, one fence wait.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "../../shaders/layout.h"
#include "../distance/field_plan.h"
#include "vulkan_context.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

constexpr int kMaxExtent = 16384;  // keeps every cost of the passes within 31 bits

template <class T>
std::uint32_t bits(T value) {
  std::uint32_t b = 0;
  std::memcpy(&b, &value, sizeof(T));
  return b;
}

template <class T>
void set_encoding(L::PassParams& pp, const detail::FieldPlan& plan) {
  pp.clamp_pos = bits(detail::encode_distance<T>(plan.clamp, plan));
  pp.clamp_neg = bits(detail::encode_distance<T>(-plan.clamp, plan));
  pp.none_pos = bits(detail::encode_distance<T>(std::numeric_limits<double>::infinity(), plan));
  pp.none_neg = bits(detail::encode_distance<T>(-std::numeric_limits<double>::infinity(), plan));
}

// The smallest cost whose distance is at or beyond the clamp, with the CPU's own comparison
// (d < clamp, d = sqrt(cost) for Euclidean).
std::uint32_t clamp_cost(const detail::FieldPlan& plan) {
  if (!std::isfinite(plan.clamp)) return L::VF_INF;
  auto distance = [&](double cost) { return plan.metric == Metric::kEuclidean ? std::sqrt(cost) : cost; };
  double c = std::ceil(plan.metric == Metric::kEuclidean ? plan.clamp * plan.clamp : plan.clamp);
  while (c > 0 && distance(c - 1) >= plan.clamp) c -= 1;
  while (distance(c) < plan.clamp) c += 1;
  return static_cast<std::uint32_t>(std::min<double>(c, L::VF_INF - 1.0));
}

struct Staging {
  std::vector<std::uint8_t> bytes;
  VkDeviceSize add(const void* data, std::size_t n) {
    const VkDeviceSize offset = (bytes.size() + 255) / 256 * 256;
    bytes.resize(offset + n);
    if (n > 0) std::memcpy(bytes.data() + offset, data, n);
    return offset;
  }
};

template <class T>
DistanceField build_field(const World& world, const DistanceOptions& options, const detail::FieldPlan& plan,
                          const std::uint32_t* stored) {
  DistanceField out;
  out.options = options;
  out.domain = plan.domain;
  out.encoding = plan.encoding;
  Grid<T> values(world.voxels.chunk_edge(), detail::field_background<T>(plan), world.voxels.bounds());
  std::vector<T> dense(static_cast<std::size_t>(plan.domain.volume()));
  for (std::size_t i = 0; i < dense.size(); ++i) {
    if constexpr (std::is_same_v<T, float>) {
      std::memcpy(&dense[i], &stored[i], sizeof(float));
    } else {
      dense[i] = static_cast<T>(stored[i]);
    }
  }
  values.copy_from_dense(plan.domain, dense.data());
  values.compact();
  out.values = std::move(values);
  return out;
}

}  // namespace

DistanceField compute_distance_field(Context& context, const World& world, const DistanceOptions& options,
                                     std::vector<PassTiming>* timings) {
  Context::Impl& ctx = context.impl();
  if (options.nearest_sites)
    throw InvalidArgument("GPU: the Vulkan backend does not compute nearest sites yet (use the CPU backend)");
  const detail::FieldPlan plan = detail::make_field_plan(world.voxels, options);
  if (!plan.unit_spacing) throw InvalidArgument("GPU: the Vulkan backend supports unit voxel spacing only");
  if (plan.domain.empty()) return voxfield::compute_distance_field(world, options);
  const Vec3i n = plan.domain.size();
  if (n.x > kMaxExtent || n.y > kMaxExtent || n.z > kMaxExtent)
    throw InvalidArgument("GPU: domain " + to_string(plan.domain) + " exceeds " + std::to_string(kMaxExtent) +
                          " voxels along an axis");
  const std::uint64_t volume = static_cast<std::uint64_t>(plan.domain.volume());
  const VkDeviceSize field_bytes = volume * 4;
  if (field_bytes > ctx.limits.maxStorageBufferRange)
    throw InvalidArgument("GPU: a " + to_string(n) + " domain needs " + std::to_string(field_bytes) +
                          " bytes per buffer, more than this device's storage-buffer range (" +
                          std::to_string(ctx.limits.maxStorageBufferRange) + ")");

  // Encoding constants (see shaders/layout.h).
  L::PassParams base{};
  base.domain_begin = {plan.domain.begin.x, plan.domain.begin.y, plan.domain.begin.z, 0};
  base.domain_size = {n.x, n.y, n.z, 0};
  base.metric = static_cast<std::uint32_t>(plan.metric);
  base.is_signed = plan.is_signed ? 1u : 0u;
  base.clamp_cost = clamp_cost(plan);
  base.bias = static_cast<std::int32_t>(plan.encoding.bias);
  base.storage = options.storage == Storage::kU8 ? L::VF_U8 : options.storage == Storage::kU16 ? L::VF_U16 : L::VF_F32;
  switch (options.storage) {
    case Storage::kU8: set_encoding<std::uint8_t>(base, plan); break;
    case Storage::kU16: set_encoding<std::uint16_t>(base, plan); break;
    case Storage::kF32: set_encoding<float>(base, plan); break;
  }
  if (plan.metric == Metric::kEuclidean && options.storage != Storage::kF32) {
    const double s = plan.encoding.scale;
    if (s != std::floor(s))
      throw InvalidArgument("GPU: Euclidean fixed point needs an integral scale on the Vulkan backend");
    base.scale_sq = static_cast<std::uint32_t>(s * s);
    const double largest = (static_cast<double>(std::min<std::uint32_t>(base.clamp_cost, 3u * kMaxExtent * kMaxExtent)) - 1) * s * s;
    if (largest >= 4294967296.0)
      throw InvalidArgument("GPU: fixed-point scale " + std::to_string(s) + " with this clamp overflows 32 bits");
  }

  // The world as brick pool + page table over the chunks the domain touches.
  const int edge = world.voxels.chunk_edge(), shift = world.voxels.chunk_shift();
  const Vec3i c0{plan.domain.begin.x >> shift, plan.domain.begin.y >> shift, plan.domain.begin.z >> shift};
  const Vec3i c1{(plan.domain.end.x - 1) >> shift, (plan.domain.end.y - 1) >> shift, (plan.domain.end.z - 1) >> shift};
  const Vec3i cd = c1 - c0 + Vec3i::splat(1);
  const std::size_t chunk_bytes = static_cast<std::size_t>(edge) * edge * edge;
  std::vector<std::uint32_t> pages(static_cast<std::size_t>(cd.x) * cd.y * cd.z);
  std::vector<std::uint8_t> bricks;
  for (int z = 0; z < cd.z; ++z)
    for (int y = 0; y < cd.y; ++y)
      for (int x = 0; x < cd.x; ++x) {
        const ChunkView<std::uint8_t> view = world.voxels.chunk_view(c0 + Vec3i{x, y, z});
        std::uint32_t& entry = pages[(static_cast<std::size_t>(z) * cd.y + y) * cd.x + x];
        if (!view.voxels) {
          entry = L::VF_UNIFORM | view.uniform_value;
          continue;
        }
        entry = static_cast<std::uint32_t>(bricks.size() / chunk_bytes);
        bricks.insert(bricks.end(), view.voxels, view.voxels + chunk_bytes);
      }
  L::WorldHeader header{};
  header.chunk_origin = {c0.x, c0.y, c0.z, 0};
  header.chunk_dims = {cd.x, cd.y, cd.z, cd.x * cd.y * cd.z};
  header.chunk_edge = static_cast<std::uint32_t>(edge);
  header.chunk_shift = static_cast<std::uint32_t>(shift);
  header.chunk_words = static_cast<std::uint32_t>(chunk_bytes / 4);
  Staging up;
  const VkDeviceSize header_at = up.add(&header, sizeof header);
  const VkDeviceSize pages_at = up.add(pages.data(), pages.size() * 4);
  const VkDeviceSize bricks_at = up.add(bricks.data(), bricks.size());

  constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                          VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  Buffer header_buf(ctx, sizeof header, kStorage, false);
  Buffer pages_buf(ctx, pages.size() * 4, kStorage, false);
  Buffer bricks_buf(ctx, std::max<std::size_t>(bricks.size(), 4), kStorage, false);
  Buffer cost0(ctx, field_bytes, kStorage, false), cost1(ctx, field_bytes, kStorage, false);
  Buffer cost2(ctx, plan.is_signed ? field_bytes : 4, kStorage, false);
  Buffer scratch_s(ctx, field_bytes, kStorage, false), scratch_t(ctx, field_bytes, kStorage, false);
  Buffer out(ctx, field_bytes, kStorage, false);
  Buffer& upload = ctx.upload_buffer(up.bytes.size());
  std::memcpy(upload.mapped(), up.bytes.data(), up.bytes.size());
  Buffer& readback = ctx.readback_buffer(field_bytes);

  // One descriptor set binds every buffer; passes differ by pipeline and push constants.
  check(vkResetDescriptorPool(ctx.device, ctx.descriptor_pool, 0), "vkResetDescriptorPool");
  VkDescriptorSetAllocateInfo dsa{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  dsa.descriptorPool = ctx.descriptor_pool;
  dsa.descriptorSetCount = 1;
  dsa.pSetLayouts = &ctx.set_layout;
  VkDescriptorSet set;
  check(vkAllocateDescriptorSets(ctx.device, &dsa, &set), "vkAllocateDescriptorSets");
  const Buffer* bound[Context::Impl::kBindings] = {&header_buf, &pages_buf, &bricks_buf, &cost0, &cost1,
                                                   &cost2,      &scratch_s, &scratch_t,  &out};
  VkDescriptorBufferInfo infos[Context::Impl::kBindings];
  VkWriteDescriptorSet writes[Context::Impl::kBindings];
  for (std::uint32_t b = 0; b < Context::Impl::kBindings; ++b) {
    infos[b] = {bound[b]->handle(), 0, VK_WHOLE_SIZE};
    writes[b] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
    writes[b].dstSet = set;
    writes[b].dstBinding = b;
    writes[b].descriptorCount = 1;
    writes[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    writes[b].pBufferInfo = &infos[b];
  }
  vkUpdateDescriptorSets(ctx.device, Context::Impl::kBindings, writes, 0, nullptr);

  VkCommandBufferAllocateInfo cba{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cba.commandPool = ctx.command_pool;
  cba.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cba.commandBufferCount = 1;
  VkCommandBuffer cmd;
  check(vkAllocateCommandBuffers(ctx.device, &cba, &cmd), "vkAllocateCommandBuffers");
  struct FreeCmd {
    Context::Impl& ctx;
    VkCommandBuffer cmd;
    ~FreeCmd() { vkFreeCommandBuffers(ctx.device, ctx.command_pool, 1, &cmd); }
  } free_cmd{ctx, cmd};
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(cmd, &begin), "vkBeginCommandBuffer");

  std::vector<std::string> pass_names;
  const bool timed = ctx.timestamps != VK_NULL_HANDLE;
  if (timed) vkCmdResetQueryPool(cmd, ctx.timestamps, 0, 64);

  const VkBufferCopy copies[3] = {{header_at, 0, sizeof header}, {pages_at, 0, pages.size() * 4},
                                  {bricks_at, 0, bricks.size()}};
  vkCmdCopyBuffer(cmd, upload.handle(), header_buf.handle(), 1, &copies[0]);
  vkCmdCopyBuffer(cmd, upload.handle(), pages_buf.handle(), 1, &copies[1]);
  if (!bricks.empty()) vkCmdCopyBuffer(cmd, upload.handle(), bricks_buf.handle(), 1, &copies[2]);
  ctx.counters.bytes_uploaded += static_cast<std::int64_t>(sizeof header + pages.size() * 4 + bricks.size());
  barrier(ctx, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
          VK_ACCESS_SHADER_READ_BIT);
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx.pipeline_layout, 0, 1, &set, 0, nullptr);

  bool first_pass = true;
  auto pass = [&](const Pipeline& pipeline, L::PassParams pp, std::uint64_t invocations, const std::string& name) {
    if (!first_pass)
      barrier(ctx, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
              VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    first_pass = false;
    const auto q = static_cast<std::uint32_t>(2 * pass_names.size());
    if (timed && q + 1 < 64) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, ctx.timestamps, q);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
    vkCmdPushConstants(cmd, ctx.pipeline_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pp, &pp);
    dispatch(ctx, cmd, invocations);
    if (timed && q + 1 < 64) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, ctx.timestamps, q + 1);
    pass_names.push_back(name);
  };
  // One separable transform: sites along x into `result`, then y and z through the other buffer.
  auto transform = [&](std::uint32_t result, std::uint32_t other, bool sites_are_air) {
    const std::string what = sites_are_air ? " (to air)" : "";
    L::PassParams pp = base;
    pp.sites_are_air = sites_are_air ? 1u : 0u;
    pp.axis = 0;
    pp.dst = result;
    pass(ctx.edt_sites, pp, static_cast<std::uint64_t>(n.y) * n.z, "rows x" + what);
    pp.axis = 1;
    pp.src = result;
    pp.dst = other;
    pass(ctx.edt_lines, pp, static_cast<std::uint64_t>(n.x) * n.z, "lines y" + what);
    pp.axis = 2;
    pp.src = other;
    pp.dst = result;
    pass(ctx.edt_lines, pp, static_cast<std::uint64_t>(n.x) * n.y, "lines z" + what);
  };
  transform(0, 1, false);
  if (plan.is_signed) transform(2, 1, true);
  L::PassParams enc = base;
  enc.src = 0;
  enc.src2 = 2;
  pass(ctx.edt_encode, enc, volume, "encode");

  barrier(ctx, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
          VK_ACCESS_TRANSFER_READ_BIT);
  const VkBufferCopy down{0, 0, field_bytes};
  vkCmdCopyBuffer(cmd, out.handle(), readback.handle(), 1, &down);
  barrier(ctx, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
          VK_ACCESS_HOST_READ_BIT);
  ctx.counters.bytes_downloaded += static_cast<std::int64_t>(field_bytes);
  check(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");
  ctx.submit_and_wait(cmd);

  if (timings) {
    timings->clear();
    if (timed && !pass_names.empty()) {
      const auto count = static_cast<std::uint32_t>(std::min<std::size_t>(2 * pass_names.size(), 64));
      std::vector<std::uint64_t> ticks(count);
      check(vkGetQueryPoolResults(ctx.device, ctx.timestamps, 0, count, ticks.size() * 8, ticks.data(), 8,
                                  VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
            "vkGetQueryPoolResults");
      for (std::size_t i = 0; 2 * i + 1 < count; ++i)
        timings->push_back({pass_names[i], static_cast<double>(ticks[2 * i + 1] - ticks[2 * i]) *
                                               ctx.timestamp_period_ns * 1e-6});
    }
  }

  const auto* stored = static_cast<const std::uint32_t*>(readback.mapped());
  switch (options.storage) {
    case Storage::kU8: return build_field<std::uint8_t>(world, options, plan, stored);
    case Storage::kU16: return build_field<std::uint16_t>(world, options, plan, stored);
    case Storage::kF32: return build_field<float>(world, options, plan, stored);
  }
  return {};
}

}  // namespace voxfield::gpu
