// voxfield render — CSG models on Vulkan: sphere tracing through the voxel compiler's octree with
// one generated kernel per variant (Palecek, "A Better Approach to SDF Decomposition", 2022), in
// waves (Laine, Karras and Aila, "Megakernels Considered Harmful", 2013; the kernels and their
// shared records are in csg_trace_glsl.cpp).
//
// Schedule. The frame (the CPU renderer's octree, camera and epsilon: csg_frame.h) is uploaded
// once: the finest cells' leaf indices, the leaves, every surface cell's constants, and each
// variant's interpreter program. Primary rays are then traced in rounds — advance (each active ray
// to its next non-empty cell), bin (queue offsets per variant, indirect dispatch sizes), scatter,
// and one indirect dispatch per variant — several rounds per submission, until a round queues no
// ray; shadow rays follow the same way from the hits; a last kernel shades. A variant's rays run
// its compiled kernel when that is ready, else the interpreter: with kCompiledWhenReady the
// variants compile on worker threads while the interpreter draws, as Palecek recommends.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <future>
#include <thread>

#include "../csg_frame.h"
#include "csg_trace_glsl.h"
#include "gpu/recorder.h"
#include "voxfield/gpu_render.h"
#include "voxfield/interrupt.h"
#include "voxfield/parallel.h"

namespace voxfield::gpu {
namespace {

struct alignas(16) F4 {
  float x = 0, y = 0, z = 0, w = 0;
};
F4 f4(const Vec3d& v, double w = 0) {
  return {static_cast<float>(v.x), static_cast<float>(v.y), static_cast<float>(v.z),
          static_cast<float>(w)};
}
F4 f4(const render_detail::Rgb& c) {
  return {static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b), 1};
}

// The records of csg_trace_glsl.cpp (std430).
struct FrameBlock {
  F4 root_lo, eye, forward, right, up, sun, full_colour;
  std::uint32_t width, height, grid_n, variants;
  float scale, epsilon;
  std::uint32_t whole_program, whole_params;
  std::uint32_t view, shadows, max_groups_x, pad1;
  F4 albedo[256];
};
struct LeafRecord {
  F4 lo, hi;
  std::int32_t state, variant;
  std::uint32_t param_base;
  std::int32_t pad;
};
struct VariantRecord {
  std::uint32_t program, lipschitz, pad0, pad1;
  F4 colour;
};
struct Push {
  std::uint32_t mode, variant;
};
constexpr VkDeviceSize kRayBytes = 48, kHitBytes = 32;
constexpr std::uint32_t kNoProgram = 0xFFFFFFFFu;
constexpr int kRoundsPerSubmit = 4;

bool lipschitz(const csg::Tape& t) {
  for (const csg::Instr& in : t.code)
    if (!in.lipschitz) return false;
  return true;
}

template <class T>
std::span<const std::uint8_t> bytes_of(const std::vector<T>& v) {
  return {reinterpret_cast<const std::uint8_t*>(v.data()), v.size() * sizeof(T)};
}

// What the frame uploads, built on the host from the octree.
struct Scene {
  FrameBlock frame{};
  std::vector<std::int32_t> grid;
  std::vector<LeafRecord> leaves;
  std::vector<float> params;
  std::vector<std::uint32_t> programs;
  std::vector<VariantRecord> variants;
  std::vector<const csg::Tape*> variant_tapes;
};

Scene build_scene(const csg::Model& model, const CsgRenderOptions& o,
                  const render_detail::CsgFrame& f, bool need_programs) {
  Scene s;
  const int depth = f.tree ? f.tree->depth : 0;
  const std::int64_t n = std::int64_t{1} << depth;
  s.grid.assign(static_cast<std::size_t>(n * n * n), -1);
  const auto program_of = [&](const csg::Tape& t, bool required) {
    if (t.registers > csg::kInterpreterRegisters) {
      if (required)
        throw InvalidArgument("GPU CSG render: a variant needs " + std::to_string(t.registers) +
                              " registers, more than the interpreter's " +
                              std::to_string(csg::kInterpreterRegisters) +
                              " (render it with compiled variants)");
      return kNoProgram;
    }
    const std::vector<std::uint32_t> p = csg::interpreter_program(t);
    const auto at = static_cast<std::uint32_t>(s.programs.size());
    s.programs.insert(s.programs.end(), p.begin(), p.end());
    return at;
  };
  const auto add_params = [&](const std::vector<double>& p) {
    const auto at = static_cast<std::uint32_t>(s.params.size());
    for (double x : p) s.params.push_back(static_cast<float>(x));
    return at;
  };
  if (f.tree) {
    const csg::Octree& t = *f.tree;
    s.leaves.reserve(t.leaves.size());
    for (std::size_t i = 0; i < t.leaves.size(); ++i) {
      const csg::OctreeLeaf& l = t.leaves[i];
      const csg::Bounds b = t.leaf_box(l);
      LeafRecord r{f4(b.lo), f4(b.hi), static_cast<std::int32_t>(l.state), l.variant, 0, 0};
      if (l.state == csg::CellState::kSurface) r.param_base = add_params(t.leaf_params(l));
      s.leaves.push_back(r);
      if (l.state == csg::CellState::kEmpty) continue;
      const std::int64_t span = std::int64_t{1} << (depth - l.level);
      for (std::int64_t z = l.z * span; z < (l.z + 1) * span; ++z)
        for (std::int64_t y = l.y * span; y < (l.y + 1) * span; ++y)
          for (std::int64_t x = l.x * span; x < (l.x + 1) * span; ++x)
            s.grid[static_cast<std::size_t>((z * n + y) * n + x)] = static_cast<std::int32_t>(i);
    }
    for (std::size_t v = 0; v < t.variants.size(); ++v) {
      const csg::Tape& tape = t.variants[v].tape;
      s.variant_tapes.push_back(&tape);
      s.variants.push_back({program_of(tape, need_programs), lipschitz(tape) ? 1u : 0u, 0, 0,
                            f4(render_detail::variant_colour(static_cast<int>(v)))});
    }
  } else {
    // Without pruning: one surface cell, the traced box, with the whole tape as its variant.
    s.leaves.push_back(
        {f4(f.traced_box.lo), f4(f.traced_box.hi), 2, 0, add_params(f.whole.params), 0});
    s.grid[0] = 0;
    s.variant_tapes.push_back(&f.whole);
    s.variants.push_back({program_of(f.whole, need_programs), lipschitz(f.whole) ? 1u : 0u, 0, 0,
                          f4(render_detail::Rgb{0.3, 0.3, 0.3})});
  }
  FrameBlock& fb = s.frame;
  const Vec3d size = f.traced_box.hi - f.traced_box.lo;
  const double edge = std::max({size.x, size.y, size.z}) / static_cast<double>(n);
  fb.root_lo = f4(f.traced_box.lo, edge);
  const Camera::Projector pj = f.camera.projector(o.width, o.height);
  fb.eye = f4(pj.eye, pj.projection == Camera::Projection::kOrthographic ? 1 : 0);
  fb.forward = f4(pj.forward);
  fb.right = f4(pj.right);
  fb.up = f4(pj.up);
  fb.sun = f4(RenderOptions{}.sun_direction.normalized());
  fb.full_colour =
      f4(f.tree ? render_detail::variant_colour(-1) : render_detail::Rgb{0.3, 0.3, 0.3});
  fb.width = static_cast<std::uint32_t>(o.width);
  fb.height = static_cast<std::uint32_t>(o.height);
  fb.grid_n = static_cast<std::uint32_t>(n);
  fb.variants = static_cast<std::uint32_t>(s.variants.size());
  fb.scale = static_cast<float>(pj.scale);
  fb.epsilon = static_cast<float>(f.epsilon);
  fb.whole_params = add_params(f.whole.params);
  fb.whole_program = program_of(f.whole, false);
  fb.view = o.view == CsgRenderOptions::View::kVariants ? 1u : 0u;
  fb.shadows = o.shadows ? 1u : 0u;
  for (int m = 0; m < 256; ++m) {
    const Rgba& c = model.palette[static_cast<std::size_t>(m)];
    fb.albedo[m] = {render_detail::srgb_to_linear(c.r), render_detail::srgb_to_linear(c.g),
                    render_detail::srgb_to_linear(c.b), 1};
  }
  if (s.programs.empty()) s.programs.push_back(0);  // no empty buffers
  if (s.params.empty()) s.params.push_back(0);
  return s;
}

}  // namespace

Image render_csg(Context& context, const csg::Model& model, const CsgRenderOptions& o,
                 CsgRenderStats* stats, const CsgGpuOptions& gpu_options, CsgGpuStats* gpu_stats) {
  if (o.width <= 0 || o.height <= 0 || o.width > 16384 || o.height > 16384)
    throw InvalidArgument("GPU CSG render: image size out of range (1..16384 per side)");
  if (o.prune && (o.depth < 0 || o.depth > 8))
    throw InvalidArgument("GPU CSG render: octree depth " + std::to_string(o.depth) +
                          " out of range (0..8)");
  Context::Impl& c = context.impl();
  c.require_device();
  using Evaluators = CsgGpuOptions::Evaluators;
  const render_detail::CsgFrame f = render_detail::prepare_csg_frame(model, o);
  Scene s = build_scene(model, o, f, gpu_options.evaluators == Evaluators::kInterpreter);
  s.frame.max_groups_x = c.limits.maxComputeWorkGroupCount[0];
  const auto render_start = std::chrono::steady_clock::now();
  const Counters before = c.counters;

  // Kernels: the fixed ones now; each variant's either now (kCompiled) or on worker threads.
  const std::string common = csg_trace::common();
  const Kernel& init = c.kernels.from_glsl(c.device, "csg-init", common + csg_trace::init_main());
  const Kernel& advance =
      c.kernels.from_glsl(c.device, "csg-advance", common + csg_trace::advance_main());
  const Kernel& bin = c.kernels.from_glsl(c.device, "csg-bin", common + csg_trace::bin_main());
  const Kernel& scatter =
      c.kernels.from_glsl(c.device, "csg-scatter", common + csg_trace::scatter_main());
  const Kernel& shade =
      c.kernels.from_glsl(c.device, "csg-shade", common + csg_trace::shade_main());
  const Kernel* interpreter = nullptr;
  if (gpu_options.evaluators != Evaluators::kCompiled)
    interpreter = &c.kernels.from_glsl(
        c.device, "csg-march-interpreter",
        common + csg_trace::march_main("float vf_eval(vec3 p, uint base, out uint m) {\n"
                                       "  return vf_interpret(vinfo[pc.variant].program, p, base, "
                                       "m);\n}\n"));
  const std::size_t n_variants = s.variants.size();
  const auto variant_text = [&](std::size_t v) {
    const std::string fn = "vf_variant_" + std::to_string(v);
    return common + csg::glsl_variant(*s.variant_tapes[v], static_cast<int>(v)) +
           csg_trace::march_main("float vf_eval(vec3 p, uint base, out uint m) {\n  return " + fn +
                                 "(p, base, m);\n}\n");
  };
  std::vector<const Kernel*> compiled(n_variants, nullptr);
  std::vector<std::vector<std::uint32_t>> spirv(n_variants);
  std::vector<std::string> texts(n_variants);
  std::vector<std::atomic<bool>> ready(n_variants);
  std::atomic<bool> stop{false};
  std::future<void> compiling;
  const auto compile_start = std::chrono::steady_clock::now();
  CsgGpuStats g;
  if (gpu_options.evaluators == Evaluators::kCompiled) {
    for (std::size_t v = 0; v < n_variants; ++v)
      compiled[v] =
          &c.kernels.from_glsl(c.device, "csg-variant-" + std::to_string(v), variant_text(v));
    g.compile_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - compile_start)
            .count();
  } else if (gpu_options.evaluators == Evaluators::kCompiledWhenReady) {
    // Variants made by an earlier frame are used at once; a variant beyond the interpreter's
    // registers has no placeholder, so it is compiled first; the rest compile on worker threads.
    for (std::size_t v = 0; v < n_variants; ++v) {
      texts[v] = variant_text(v);
      compiled[v] = c.kernels.find_glsl(texts[v]);
      if (!compiled[v] && s.variants[v].program == kNoProgram)
        compiled[v] = &c.kernels.from_glsl(c.device, "csg-variant-" + std::to_string(v), texts[v]);
    }
    compiling = std::async(std::launch::async, [&] {
      parallel_for(n_variants, 1, [&](std::size_t v0, std::size_t v1) {
        for (std::size_t v = v0; v < v1 && !stop; ++v) {
          if (compiled[v]) continue;  // written before this thread started
          spirv[v] = compile_glsl("csg-variant-" + std::to_string(v), texts[v]);
          ready[v].store(true, std::memory_order_release);
        }
      });
    });
  }
  // The compile threads read `s` and the kernels' text: they are stopped before anything goes.
  struct StopCompiling {
    std::atomic<bool>& stop;
    std::future<void>& f;
    ~StopCompiling() {
      stop = true;
      if (f.valid()) f.wait();
    }
  } stop_compiling{stop, compiling};
  const auto adopt_ready = [&] {
    for (std::size_t v = 0; v < n_variants; ++v)
      if (!compiled[v] && ready[v].load(std::memory_order_acquire))
        compiled[v] =
            &c.kernels.adopt_glsl(c.device, "csg-variant-" + std::to_string(v), texts[v], spirv[v]);
  };

  // Buffers: the scene (uploaded once), the rays and their bookkeeping, the pixels.
  const VkBufferUsageFlags storage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                     VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                     VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
  const std::uint64_t pixels = static_cast<std::uint64_t>(o.width) * o.height;
  const std::span<const std::uint8_t> uploads[] = {
      {reinterpret_cast<const std::uint8_t*>(&s.frame), sizeof s.frame},
      bytes_of(s.grid),
      bytes_of(s.leaves),
      bytes_of(s.params),
      bytes_of(s.programs),
      bytes_of(s.variants)};
  std::vector<Buffer> in;
  VkDeviceSize upload_bytes = 0;
  for (const auto& u : uploads) {
    if (u.size() > c.limits.maxStorageBufferRange)
      throw InvalidArgument("GPU CSG render: " + std::to_string(u.size()) +
                            " bytes of octree data in one buffer, more than this device's "
                            "storage-buffer range (use a smaller depth)");
    in.emplace_back(c, u.size(), storage, false);
    upload_bytes += (u.size() + 15) / 16 * 16;
  }
  if (pixels * kRayBytes > c.limits.maxStorageBufferRange)
    throw InvalidArgument("GPU CSG render: a " + std::to_string(o.width) + " x " +
                          std::to_string(o.height) + " picture needs " +
                          std::to_string(pixels * kRayBytes) +
                          " bytes of rays in one buffer, more than this device's storage-buffer "
                          "range (" +
                          std::to_string(c.limits.maxStorageBufferRange) + ")");
  Buffer rays(c, pixels * kRayBytes, storage, false), hits(c, pixels * kHitBytes, storage, false);
  const VkDeviceSize bins_bytes = 16 + 12 * n_variants;
  Buffer bins(c, bins_bytes, storage, false);
  Buffer args(c, 12 * n_variants, storage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, false);
  Buffer queue(c, pixels * 4, storage, false), out(c, pixels * 4, storage, false);
  Buffer& staging = c.upload_buffer(upload_bytes);
  Buffer& readback = c.readback_buffer(std::max<VkDeviceSize>(pixels * 4, 16));
  std::array<Binding, 12> all{&in[0], &in[1], &in[2], &in[3], &in[4], &in[5],
                              &rays,  &hits,  &bins,  &args,  &queue, &out};

  {
    Recorder rec(c);
    VkDeviceSize at = 0;
    for (std::size_t b = 0; b < in.size(); ++b) {
      std::memcpy(static_cast<std::uint8_t*>(staging.mapped()) + at, uploads[b].data(),
                  uploads[b].size());
      rec.copy(staging, at, in[b], 0, uploads[b].size());
      at += (uploads[b].size() + 15) / 16 * 16;
    }
    c.counters.bytes_uploaded += static_cast<std::int64_t>(upload_bytes);
    rec.dispatch(init, all, Push{0, 0}, pixels);
    rec.submit();
  }

  const int max_rounds = 3 * (1 << (f.tree ? f.tree->depth : 0)) + 4;
  // Progress in submissions (a bound: most frames end far sooner).
  Progress progress(o.interrupter, "rendering " + model.name + " on the GPU",
                    2 * (max_rounds / kRoundsPerSubmit + 1));
  const auto trace = [&](std::uint32_t mode) {
    for (int round = 0;;) {
      if (!progress.advance()) progress.throw_if_cancelled();
      adopt_ready();
      Recorder rec(c);
      if (mode == 1 && round == 0) rec.dispatch(init, all, Push{1, 0}, pixels);
      for (int k = 0; k < kRoundsPerSubmit; ++k, ++round) {
        rec.fill(bins, 0, bins_bytes, 0);
        rec.dispatch(advance, all, Push{mode, 0}, pixels);
        const Push p0{mode, 0};
        rec.dispatch_groups(bin, Recorder::Buffers(all), &p0, sizeof p0, {1, 1, 1});
        rec.dispatch(scatter, all, Push{mode, 0}, pixels);
        for (std::size_t v = 0; v < n_variants; ++v) {
          const Kernel& k_v = compiled[v] ? *compiled[v] : *interpreter;
          const Push p{mode, static_cast<std::uint32_t>(v)};
          rec.dispatch_indirect(k_v, all, &p, sizeof p, args, 12 * v);
          ++(compiled[v] ? g.compiled_dispatches : g.interpreted_dispatches);
        }
        ++g.rounds;
      }
      rec.copy(bins, 0, readback, 0, 4);  // the last round's queued rays
      rec.submit();
      std::uint32_t queued = 0;
      std::memcpy(&queued, readback.mapped(), 4);
      if (queued == 0) return;
      if (round > max_rounds)
        throw InvalidArgument("GPU CSG render: rays still queued after " + std::to_string(round) +
                              " rounds (more cells than a ray can cross)");
    }
  };
  trace(0);
  // Hits on full cells' faces take their normal and material from the whole tape, as on the CPU,
  // before the shadow rays leave from them: by the interpreter, or compiled when the whole tape
  // is beyond the interpreter's registers.
  const bool full_cells = std::any_of(s.leaves.begin(), s.leaves.end(),
                                      [](const LeafRecord& l) { return l.state == 1; });
  if (full_cells) {
    const std::string eval =
        s.frame.whole_program != kNoProgram
            ? "float vf_eval(vec3 p, uint base, out uint m) {\n  return "
              "vf_interpret(fr.whole_program, p, base, m);\n}\n"
            : csg::glsl_variant(f.whole, static_cast<int>(n_variants)) +
                  "float vf_eval(vec3 p, uint base, out uint m) {\n  return vf_variant_" +
                  std::to_string(n_variants) + "(p, base, m);\n}\n";
    const Kernel& full = c.kernels.from_glsl(c.device, "csg-full-cell-hits",
                                             common + csg_trace::full_hits_main(eval));
    Recorder rec(c);
    rec.dispatch(full, all, Push{0, 0}, pixels);
    rec.submit();
  }
  if (o.shadows) trace(1);
  {
    Recorder rec(c);
    rec.dispatch(shade, all, Push{0, 0}, pixels);
    rec.copy(out, 0, readback, 0, pixels * 4);
    rec.submit();
  }
  c.counters.bytes_downloaded += static_cast<std::int64_t>(pixels * 4);
  Image image(o.width, o.height);
  const auto* px = static_cast<const std::uint32_t*>(readback.mapped());
  for (std::uint64_t i = 0; i < pixels; ++i) {
    image.rgb[3 * i] = static_cast<std::uint8_t>(px[i] & 0xFF);
    image.rgb[3 * i + 1] = static_cast<std::uint8_t>((px[i] >> 8) & 0xFF);
    image.rgb[3 * i + 2] = static_cast<std::uint8_t>((px[i] >> 16) & 0xFF);
  }
  stop = true;
  if (compiling.valid()) compiling.get();  // a generated shader that failed to compile is an error
  adopt_ready();                           // kept for the next frame
  for (const Kernel* k : compiled) g.variants_compiled += k != nullptr;
  g.variants = static_cast<int>(n_variants);
  const Counters after = c.counters;
  g.dispatches = after.dispatches - before.dispatches;
  g.submits = after.submits - before.submits;
  if (stats) {
    *stats = {};
    stats->octree_ms = f.octree_ms;
    stats->render_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - render_start)
            .count();
    stats->rays = static_cast<std::int64_t>(pixels);
    stats->variants = static_cast<int>(f.tree ? f.tree->variants.size() : 1);
  }
  if (gpu_stats) *gpu_stats = g;
  return image;
}

}  // namespace voxfield::gpu
