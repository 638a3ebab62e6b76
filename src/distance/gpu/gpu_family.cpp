// voxfield GPU backend — the dissertation's algorithm family on Vulkan: jump flooding (the
// dissertation's value-propagating jfa-seed, and JFA, JFA+1, JFA+2) as one dispatch per pass with
// a pipeline barrier between passes, all passes of a field in one command buffer (a fixed number
// of passes: no read-back to decide when to stop); the Fast Iterative Method as Jacobi passes that
// stop themselves through indirect dispatch (src/distance/gpu/shaders/fim.comp); hybrid and LOD as
// JFA then FIM. The problem set-up and the field assembly are the CPU's
// (src/distance/family_driver.h), and the passes compute exactly what the CPU's do, so the fields
// are the same bit for bit.
#include <chrono>
#include <cstring>

#include "../family_driver.h"
#include "distance_shaders.h"
#include "gpu/recorder.h"
#include "gpu/split_buffer.h"
#include "shaders/layout.h"
#include "voxfield/gpu_distance.h"

namespace voxfield::gpu {
namespace {

namespace L = layout;

std::vector<int> extra_steps(Algorithm a) {
  switch (a) {
    case Algorithm::kJfa:
      return {};
    case Algorithm::kJfa1:
      return {1};
    case Algorithm::kJfa2:
      return {2, 1};
    case Algorithm::kJfaSeed:
      return {};
    case Algorithm::kFim:
      return {};
    case Algorithm::kHybrid:
      return {};
    case Algorithm::kLod:
      return {};
    default:
      throw InvalidArgument(std::string("GPU: the ") + algorithm_name(a) +
                            " algorithm is not on the Vulkan backend (brute force and "
                            "brute-chunked are CPU references)");
  }
}

// A ping-pong buffer (both halves, `bytes`) is bound as split_buffer.h's windows.
void check_ping_pong(const Context::Impl& ctx, std::size_t voxels, VkDeviceSize bytes,
                     const std::string& label) {
  check_split_binding(
      ctx, bytes,
      "GPU: " + label + "'s ping-pong buffer over " + std::to_string(voxels) + " voxels");
}

// Runs one pass of `kernel` per step over a ping-pong buffer of p.size() elements (both halves
// in one buffer), starting from `initial`, in one command buffer (the recorder puts a barrier
// between passes, as each reads what the last wrote); returns the last pass's elements.
std::vector<std::uint8_t> ping_pong(Context::Impl& ctx, const Kernel& kernel,
                                    const detail::DenseProblem& p,
                                    const std::vector<std::uint8_t>& initial,
                                    std::size_t element_bytes, const std::vector<int>& steps,
                                    const std::string& label, std::vector<PassTiming>* timings) {
  const std::size_t n = p.size();
  const VkDeviceSize half = static_cast<VkDeviceSize>(n) * element_bytes;
  check_ping_pong(ctx, n, 2 * half, label);
  Buffer data(ctx, 2 * half,
              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                  VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
              false);
  Buffer& upload = ctx.upload_buffer(half);
  std::memcpy(upload.mapped(), initial.data(), half);
  Buffer& readback = ctx.readback_buffer(half);
  Recorder rec(ctx);
  rec.copy(upload, 0, data, 0, half);
  std::uint32_t src = 0;
  for (const int step : steps) {
    L::JfaParams jp{};
    jp.size = {p.n.x, p.n.y, p.n.z, static_cast<std::int32_t>(split_part_shift(ctx))};
    jp.step = step;
    jp.metric = static_cast<std::uint32_t>(p.metric);
    jp.src = src;
    jp.dst = src == 0 ? static_cast<std::uint32_t>(n) : 0u;
    const int pass = timings ? rec.begin_pass() : -1;
    rec.dispatch(kernel, split_bindings(data, ctx), jp, n);
    rec.end_pass(pass, label + " step " + std::to_string(step));
    src = jp.dst;
  }
  rec.copy(data, static_cast<VkDeviceSize>(src) * element_bytes, readback, 0, half);
  rec.submit();
  if (timings) timings->insert(timings->end(), rec.timings().begin(), rec.timings().end());
  std::vector<std::uint8_t> result(half);
  std::memcpy(result.data(), readback.mapped(), half);
  return result;
}

// Jump flooding of sites; they come back for the CPU's assembly.
detail::DenseSolution flood(Context::Impl& ctx, const detail::DenseProblem& p,
                            const std::vector<int>& extra, AlgorithmStats& stats,
                            std::vector<PassTiming>* timings) {
  const std::vector<int> steps = detail::jfa_steps(p, extra);
  const std::vector<detail::JfaSite> seeds = detail::jfa_seeds(p);
  const std::size_t n = p.size();
  std::vector<std::uint8_t> packed(n * 8);
  auto* words = reinterpret_cast<std::uint32_t*>(packed.data());
  for (std::size_t i = 0; i < n; ++i) {
    const detail::JfaSite s = seeds[i];
    words[2 * i] = s.x < 0
                       ? L::VF_INF
                       : static_cast<std::uint32_t>(s.x) | (static_cast<std::uint32_t>(s.y) << 16);
    words[2 * i + 1] = s.x < 0 ? 0u : static_cast<std::uint32_t>(s.z);
  }
  const std::vector<std::uint8_t> out =
      ping_pong(ctx, ctx.kernel(shaders::jfa()), p, packed, 8, steps, "jfa", timings);
  const auto* got = reinterpret_cast<const std::uint32_t*>(out.data());
  std::vector<detail::JfaSite> final_sites(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (got[2 * i] == L::VF_INF) continue;
    final_sites[i] = {static_cast<std::int16_t>(got[2 * i] & 0xFFFF),
                      static_cast<std::int16_t>(got[2 * i] >> 16),
                      static_cast<std::int16_t>(got[2 * i + 1])};
  }
  detail::DenseSolution solution;
  detail::jfa_solution(p, final_sites, solution);
  stats.passes += static_cast<int>(steps.size());
  stats.updates += static_cast<std::int64_t>(n) * 27 * static_cast<std::int64_t>(steps.size());
  return solution;
}

// The dissertation's value-propagating flood: 6 neighbours, distances only.
detail::DenseSolution flood_values(Context::Impl& ctx, const detail::DenseProblem& p,
                                   AlgorithmStats& stats, std::vector<PassTiming>* timings) {
  const std::vector<int> steps = detail::jfa_steps(p, {});
  const std::size_t n = p.size();
  std::vector<std::uint8_t> initial(n * 4);
  auto* values = reinterpret_cast<float*>(initial.data());
  for (std::size_t i = 0; i < n; ++i) values[i] = p.site[i] ? 0.0f : detail::kFar;
  const std::vector<std::uint8_t> out =
      ping_pong(ctx, ctx.kernel(shaders::jfa_seed()), p, initial, 4, steps, "jfa-seed", timings);
  detail::DenseSolution solution;
  solution.d.resize(n);
  std::memcpy(solution.d.data(), out.data(), n * 4);
  stats.passes += static_cast<int>(steps.size());
  stats.updates += static_cast<std::int64_t>(n) * 6 * static_cast<std::int64_t>(steps.size());
  return solution;
}

// The most Jacobi passes a field may need: values travel one voxel per pass, and a chain of
// upwind dependencies cannot be longer than a path through the domain — twice over for the
// Euclidean rule, whose chains may zig-zag. Converged passes cost an empty indirect dispatch.
std::uint32_t fim_pass_bound(const detail::DenseProblem& p) {
  const std::uint64_t sum = static_cast<std::uint64_t>(p.n.x) + p.n.y + p.n.z;
  const std::uint64_t bound = p.metric == Metric::kChebyshev ? std::max({p.n.x, p.n.y, p.n.z}) + 2u
                              : p.metric == Metric::kManhattan ? sum + 2
                                                               : 2 * sum + 8;
  return static_cast<std::uint32_t>(bound);
}

// The Fast Iterative Method as Jacobi passes over `region` from `initial` values (0 at sites),
// stopping by itself once a pass moves nothing by more than the CPU's tolerance: one command
// buffer, no read-back until the end.
detail::DenseSolution iterate(Context::Impl& ctx, const detail::DenseProblem& p,
                              const std::vector<float>& initial, const Box3i& region,
                              AlgorithmStats& stats, std::vector<PassTiming>* timings) {
  const std::size_t n = p.size();
  const VkDeviceSize half = static_cast<VkDeviceSize>(n) * 4;
  check_ping_pong(ctx, n, 2 * half, "fim");
  detail::DenseSolution solution;
  solution.d = initial;
  if (region.empty() || n == 0) return solution;
  Buffer data(ctx, 2 * half,
              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                  VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
              false);
  constexpr VkDeviceSize kControlBytes = 8 * 4;
  Buffer control(ctx, kControlBytes,
                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT |
                     VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                 false);
  const Kernel& fim = ctx.kernel(shaders::fim());
  // The update pass's workgroups, split over y as Recorder::dispatch does.
  const std::uint64_t per_group = fim.interface.invocations_per_group();
  const std::uint64_t groups = (n + per_group - 1) / per_group;
  const std::uint64_t gx = std::min<std::uint64_t>(groups, ctx.limits.maxComputeWorkGroupCount[0]);
  const std::uint64_t gy = (groups + gx - 1) / gx;
  if (gy > ctx.limits.maxComputeWorkGroupCount[1])
    throw InvalidArgument("GPU: the domain exceeds the device's dispatch limits");
  const std::uint32_t control_init[8] = {
      0, 0, 0, 0, static_cast<std::uint32_t>(gx), static_cast<std::uint32_t>(gy), 1, 0};
  Buffer& upload = ctx.upload_buffer(half + kControlBytes);
  std::memcpy(upload.mapped(), initial.data(), half);
  std::memcpy(static_cast<std::uint8_t*>(upload.mapped()) + half, control_init, kControlBytes);
  Buffer& readback = ctx.readback_buffer(half + kControlBytes);
  const std::uint32_t passes = fim_pass_bound(p);

  L::FimParams fp{};
  fp.size = {p.n.x, p.n.y, p.n.z, L::VF_FIM_UPDATE};
  fp.region_begin = {region.begin.x, region.begin.y, region.begin.z,
                     static_cast<std::int32_t>(split_part_shift(ctx))};
  fp.region_end = {region.end.x, region.end.y, region.end.z, 0};
  fp.metric = static_cast<std::uint32_t>(p.metric);
  fp.eps = p.metric == Metric::kEuclidean ? 1e-5f : 0.0f;  // the CPU's tolerance
  Recorder rec(ctx);
  const int timed = timings ? rec.begin_pass() : -1;
  const VkBufferCopy in{0, 0, half}, in_control{half, 0, kControlBytes};
  rec.copy({{&upload, &data, {&in, 1}}, {&upload, &control, {&in_control, 1}}});
  // The values' windows at bindings 0, 2, 3 and 4, the control words at 1.
  const auto values = split_bindings(data, ctx);
  const std::array<Binding, 5> bound{values[0], &control, values[1], values[2], values[3]};
  std::uint32_t src = 0;
  for (std::uint32_t k = 0; k < passes; ++k) {
    fp.size.w = L::VF_FIM_UPDATE;
    fp.src = src;
    fp.dst = src == 0 ? static_cast<std::uint32_t>(n) : 0u;
    rec.dispatch_indirect(fim, bound, &fp, sizeof fp, control, L::VF_FIM_GROUPS * 4);
    fp.size.w = L::VF_FIM_CONTROL;
    rec.dispatch_groups(fim, bound, &fp, sizeof fp, {1, 1, 1});
    src = fp.dst;
  }
  fp.size.w = L::VF_FIM_RESOLVE;
  rec.dispatch(fim, bound, fp, n);
  rec.end_pass(timed, "fim");
  const VkBufferCopy out{0, 0, half}, out_control{0, half, kControlBytes};
  rec.copy({{&data, &readback, {&out, 1}}, {&control, &readback, {&out_control, 1}}});
  rec.submit();
  std::uint32_t words[8];
  std::memcpy(words, static_cast<const std::uint8_t*>(readback.mapped()) + half, sizeof words);
  if (words[L::VF_FIM_CONVERGED] != 1u)
    throw Error("GPU: fim did not converge within " + std::to_string(passes) +
                " passes");  // the bound says it must
  std::memcpy(solution.d.data(), readback.mapped(), half);
  stats.iterations += static_cast<int>(words[L::VF_FIM_PASSES]);
  stats.updates += static_cast<std::int64_t>(region.volume()) * words[L::VF_FIM_PASSES];
  if (timings && !rec.timings().empty())
    timings->push_back(
        {"fim (" + std::to_string(words[L::VF_FIM_PASSES]) + " passes)", rec.timings().front().ms});
  return solution;
}

// The CPU's LOD region: the world's chunks that meet the focus box, in domain coordinates.
Box3i lod_region(const detail::DenseProblem& p, const Box3i& focus) {
  const int e = p.chunk_edge;
  auto down = [e](int v) { return (v >= 0 ? v / e : -((-v + e - 1) / e)) * e; };
  const Box3i chunks{
      {down(focus.begin.x), down(focus.begin.y), down(focus.begin.z)},
      {down(focus.end.x - 1) + e, down(focus.end.y - 1) + e, down(focus.end.z - 1) + e}};
  return Box3i{chunks.begin - p.box.begin, chunks.end - p.box.begin}.intersect(
      Box3i::from_size(p.n));
}

detail::DenseSolution solve(Context::Impl& ctx, const detail::DenseProblem& p,
                            const AlgorithmOptions& a, const std::vector<int>& extra,
                            AlgorithmStats& st, std::vector<PassTiming>* timings) {
  switch (a.algorithm) {
    case Algorithm::kJfaSeed:
      return flood_values(ctx, p, st, timings);
    case Algorithm::kFim: {
      std::vector<float> initial(p.size());
      for (std::size_t i = 0; i < p.size(); ++i) initial[i] = p.site[i] ? 0.0f : detail::kFar;
      return iterate(ctx, p, initial, Box3i::from_size(p.n), st, timings);
    }
    case Algorithm::kHybrid:
    case Algorithm::kLod: {
      // Jump flooding, then FIM from its values (everywhere, or in the focus chunks): two submits.
      const detail::DenseSolution jfa = flood(ctx, p, extra, st, timings);
      const Box3i region =
          a.algorithm == Algorithm::kHybrid ? Box3i::from_size(p.n) : lod_region(p, *a.focus);
      return iterate(ctx, p, jfa.d, region, st, timings);
    }
    default:
      return flood(ctx, p, extra, st, timings);
  }
}

}  // namespace

DistanceField compute_distance_field(Context& context, const World& world,
                                     const DistanceOptions& options,
                                     const AlgorithmOptions& algorithm, AlgorithmStats* stats,
                                     std::vector<PassTiming>* timings) {
  if (timings) timings->clear();
  if (algorithm.algorithm == Algorithm::kExact) {
    const auto t0 = std::chrono::steady_clock::now();
    DistanceField f = compute_distance_field(context, world, options, timings);
    if (stats) {
      *stats = AlgorithmStats{};
      stats->ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    return f;
  }
  const std::vector<int> extra = extra_steps(algorithm.algorithm);
  if (options.spacing != std::array<double, 3>{1, 1, 1})
    throw InvalidArgument(
        "GPU: the algorithm family on the Vulkan backend supports unit voxel spacing only");
  const Algorithm alg = algorithm.algorithm;
  if (options.nearest_sites &&
      (alg == Algorithm::kFim || alg == Algorithm::kHybrid || alg == Algorithm::kLod))
    throw InvalidArgument(std::string("GPU: ") + algorithm_name(alg) +
                          " on the Vulkan backend does not track nearest sites (its Jacobi passes "
                          "carry distances only)");
  Context::Impl& ctx = context.impl();
  return detail::compute_with_solver(
      world, options, algorithm, stats,
      [&](const detail::DenseProblem& p, const AlgorithmOptions& a, AlgorithmStats& st) {
        return solve(ctx, p, a, extra, st, timings);
      });
}

}  // namespace voxfield::gpu
