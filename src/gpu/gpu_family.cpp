// voxfield GPU backend — the dissertation's algorithm family on Vulkan: jump flooding (the
// dissertation's value-propagating jfa-seed, and JFA, JFA+1, JFA+2) as one dispatch per pass with a pipeline barrier between passes, all passes of a
// field in one command buffer (a fixed number of passes: no read-back to decide when to stop).
// The problem set-up and the field assembly are the CPU's (src/distance/family_driver.h), and the
// passes compute exactly what the CPU's do, so the fields are the same bit for bit.
#include <chrono>
#include <cstring>

#include "../../shaders/layout.h"
#include "../distance/family_driver.h"
#include "vulkan_context.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

std::vector<int> extra_steps(Algorithm a) {
  switch (a) {
    case Algorithm::kJfa: return {};
    case Algorithm::kJfa1: return {1};
    case Algorithm::kJfa2: return {2, 1};
    case Algorithm::kJfaSeed: return {};
    default:
      throw InvalidArgument(std::string("GPU: the ") + algorithm_name(a) +
                            " algorithm is not on the Vulkan backend yet (exact, jfa-seed, jfa, jfa+1 and jfa+2 are)");
  }
}

// Runs one pass of `pipeline` per step over a ping-pong buffer of p.size() elements (both halves
// in one buffer), starting from `initial`, in one command buffer with a barrier between passes;
// returns the last pass's elements.
std::vector<std::uint8_t> ping_pong(Context::Impl& ctx, const Pipeline& pipeline, const detail::DenseProblem& p,
                                    const std::vector<std::uint8_t>& initial, std::size_t element_bytes,
                                    const std::vector<int>& steps, const std::string& label,
                                    std::vector<PassTiming>* timings) {
  const std::size_t n = p.size();
  const VkDeviceSize half = static_cast<VkDeviceSize>(n) * element_bytes;
  if (2 * half > ctx.limits.maxStorageBufferRange)
    throw InvalidArgument("GPU: " + std::to_string(n) + " voxels exceed this device's storage-buffer range for " + label);
  Buffer data(ctx, 2 * half,
              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false);
  Buffer& upload = ctx.upload_buffer(half);
  std::memcpy(upload.mapped(), initial.data(), half);
  Buffer& readback = ctx.readback_buffer(half);
  const Buffer* bound[1] = {&data};
  const VkDescriptorSet set = ctx.bind(ctx.jfa_layout, bound);
  const bool timed = timings && ctx.timestamps != VK_NULL_HANDLE && steps.size() <= 31;
  std::uint32_t src = 0;
  ctx.run_commands([&](VkCommandBuffer cmd) {
    if (timed) vkCmdResetQueryPool(cmd, ctx.timestamps, 0, 64);
    const VkBufferCopy in{0, 0, half};
    vkCmdCopyBuffer(cmd, upload.handle(), data.handle(), 1, &in);
    ctx.counters.bytes_uploaded += static_cast<std::int64_t>(half);
    barrier(ctx, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
            VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline.pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, ctx.jfa_layout.pipeline, 0, 1, &set, 0, nullptr);
    for (std::size_t k = 0; k < steps.size(); ++k) {
      if (k > 0)
        barrier(ctx, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
      L::JfaParams jp{};
      jp.size = {p.n.x, p.n.y, p.n.z, 0};
      jp.step = steps[k];
      jp.metric = static_cast<std::uint32_t>(p.metric);
      jp.src = src;
      jp.dst = src == 0 ? static_cast<std::uint32_t>(n) : 0u;
      vkCmdPushConstants(cmd, ctx.jfa_layout.pipeline, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof jp, &jp);
      if (timed) vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, ctx.timestamps, static_cast<std::uint32_t>(2 * k));
      dispatch(ctx, cmd, n);
      if (timed)
        vkCmdWriteTimestamp(cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, ctx.timestamps, static_cast<std::uint32_t>(2 * k + 1));
      src = jp.dst;
    }
    barrier(ctx, cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
            VK_ACCESS_TRANSFER_READ_BIT);
    const VkBufferCopy out{static_cast<VkDeviceSize>(src) * element_bytes, 0, half};
    vkCmdCopyBuffer(cmd, data.handle(), readback.handle(), 1, &out);
    barrier(ctx, cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
            VK_ACCESS_HOST_READ_BIT);
    ctx.counters.bytes_downloaded += static_cast<std::int64_t>(half);
  });
  if (timed) {
    std::vector<std::uint64_t> ticks(2 * steps.size());
    check(vkGetQueryPoolResults(ctx.device, ctx.timestamps, 0, static_cast<std::uint32_t>(ticks.size()), ticks.size() * 8,
                                ticks.data(), 8, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    for (std::size_t k = 0; k < steps.size(); ++k)
      timings->push_back({label + " step " + std::to_string(steps[k]),
                          static_cast<double>(ticks[2 * k + 1] - ticks[2 * k]) * ctx.timestamp_period_ns * 1e-6});
  }
  std::vector<std::uint8_t> result(half);
  std::memcpy(result.data(), readback.mapped(), half);
  return result;
}

// Jump flooding of sites; they come back for the CPU's assembly.
detail::DenseSolution flood(Context::Impl& ctx, const detail::DenseProblem& p, const std::vector<int>& extra,
                            AlgorithmStats& stats, std::vector<PassTiming>* timings) {
  const std::vector<int> steps = detail::jfa_steps(p, extra);
  const std::vector<detail::JfaSite> seeds = detail::jfa_seeds(p);
  const std::size_t n = p.size();
  std::vector<std::uint8_t> packed(n * 8);
  auto* words = reinterpret_cast<std::uint32_t*>(packed.data());
  for (std::size_t i = 0; i < n; ++i) {
    const detail::JfaSite s = seeds[i];
    words[2 * i] = s.x < 0 ? L::VF_INF : static_cast<std::uint32_t>(s.x) | (static_cast<std::uint32_t>(s.y) << 16);
    words[2 * i + 1] = s.x < 0 ? 0u : static_cast<std::uint32_t>(s.z);
  }
  const std::vector<std::uint8_t> out = ping_pong(ctx, ctx.jfa, p, packed, 8, steps, "jfa", timings);
  const auto* got = reinterpret_cast<const std::uint32_t*>(out.data());
  std::vector<detail::JfaSite> final_sites(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (got[2 * i] == L::VF_INF) continue;
    final_sites[i] = {static_cast<std::int16_t>(got[2 * i] & 0xFFFF), static_cast<std::int16_t>(got[2 * i] >> 16),
                      static_cast<std::int16_t>(got[2 * i + 1])};
  }
  detail::DenseSolution solution;
  detail::jfa_solution(p, final_sites, solution);
  stats.passes += static_cast<int>(steps.size());
  stats.updates += static_cast<std::int64_t>(n) * 27 * static_cast<std::int64_t>(steps.size());
  return solution;
}

// The dissertation's value-propagating flood: 6 neighbours, distances only.
detail::DenseSolution flood_values(Context::Impl& ctx, const detail::DenseProblem& p, AlgorithmStats& stats,
                                   std::vector<PassTiming>* timings) {
  const std::vector<int> steps = detail::jfa_steps(p, {});
  const std::size_t n = p.size();
  std::vector<std::uint8_t> initial(n * 4);
  auto* values = reinterpret_cast<float*>(initial.data());
  for (std::size_t i = 0; i < n; ++i) values[i] = p.site[i] ? 0.0f : detail::kFar;
  const std::vector<std::uint8_t> out = ping_pong(ctx, ctx.jfa_seed, p, initial, 4, steps, "jfa-seed", timings);
  detail::DenseSolution solution;
  solution.d.resize(n);
  std::memcpy(solution.d.data(), out.data(), n * 4);
  stats.passes += static_cast<int>(steps.size());
  stats.updates += static_cast<std::int64_t>(n) * 6 * static_cast<std::int64_t>(steps.size());
  return solution;
}

}  // namespace

DistanceField compute_distance_field(Context& context, const World& world, const DistanceOptions& options,
                                     const AlgorithmOptions& algorithm, AlgorithmStats* stats,
                                     std::vector<PassTiming>* timings) {
  if (timings) timings->clear();
  if (algorithm.algorithm == Algorithm::kExact) {
    const auto t0 = std::chrono::steady_clock::now();
    DistanceField f = compute_distance_field(context, world, options, timings);
    if (stats) {
      *stats = AlgorithmStats{};
      stats->ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    return f;
  }
  const std::vector<int> extra = extra_steps(algorithm.algorithm);
  if (options.spacing != std::array<double, 3>{1, 1, 1})
    throw InvalidArgument("GPU: jump flooding on the Vulkan backend supports unit voxel spacing only");
  Context::Impl& ctx = context.impl();
  return detail::compute_with_solver(
      world, options, algorithm, stats,
      [&](const detail::DenseProblem& p, const AlgorithmOptions& a, AlgorithmStats& st) {
        return a.algorithm == Algorithm::kJfaSeed ? flood_values(ctx, p, st, timings) : flood(ctx, p, extra, st, timings);
      });
}

}  // namespace voxfield::gpu
