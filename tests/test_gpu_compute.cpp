// The GPU compute layer on its own (a test of internals: src/gpu/kernel.h, recorder.h). Shaders are
// reflected from their SPIR-V and checked against the C++ structures they share; generated GLSL is
// compiled at run time and run; the recorder's derived barriers are counted for chains of known
// hazards, with the Khronos synchronisation validation watching for any it missed.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <numeric>
#include <optional>

#include "csg_examples.h"
#include "distance_shaders.h"
#include "gpu/recorder.h"
#include "render_shaders.h"
#include "shaders/layout.h"
#include "voxfield/csg_compile.h"

using namespace voxfield;
using namespace voxfield::gpu;

namespace {

std::shared_ptr<Context> validated() {
  static std::shared_ptr<Context> ctx = [] {
    ContextOptions o;
    o.validation = true;
    return Context::create(o);
  }();
  return ctx;
}

#define REQUIRE_GPU()                                                            \
  if (!built_with_vulkan() || std::getenv("VOXFIELD_SKIP_GPU_TESTS") != nullptr) \
  GTEST_SKIP() << "no Vulkan backend wanted"

// out[i] = a[i] * 2 + k: a read-only, out write-only.
const char* kScale = R"(#version 450
layout(local_size_x = 32) in;
layout(std430, binding = 0) readonly buffer A { float a[]; };
layout(std430, binding = 1) writeonly buffer Out { float o[]; };
layout(push_constant) uniform P { float k; uint n; } p;
void main() {
  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  if (i < p.n) o[i] = a[i] * 2.0 + p.k;
}
)";

// b[i] += 1, read-write.
const char* kIncrement = R"(#version 450
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer B { float b[]; };
layout(push_constant) uniform P { float k; uint n; } p;
void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i < p.n) b[i] += 1.0;
}
)";

struct ScaleParams {
  float k;
  std::uint32_t n;
};

constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT;

}  // namespace

TEST(GpuCompute, EveryShaderDeclaresWhatItsCppSideSends) {
  REQUIRE_GPU();
  for (const ShaderSource& s : {shaders::edt_sites(), shaders::edt_lines(), shaders::edt_encode(),
                                shaders::edt_columns()}) {
    const ShaderInterface i = reflect(s.name, s.spirv);
    EXPECT_EQ(i.push_bytes, sizeof(layout::PassParams)) << s.name;
    // Eleven buffers, the brick pool, the field and its sites each in four windows
    // (split_buffer.h), and a slab's column neighbours: the binding plan FieldEngine::bindings()
    // sends.
    EXPECT_LE(i.buffers.size(), 12u + 3u * (layout::VF_SPLIT_PARTS - 1)) << s.name;
    // The neighbour tables: written by edt_columns alone.
    if (i.buffers.size() > 20)
      EXPECT_EQ(i.buffers.at(20),
                std::string(s.name) == "edt_columns" ? Access::kReadWrite : Access::kRead)
          << s.name;
    EXPECT_EQ(i.buffers.at(0), Access::kRead) << s.name << ": the header is read-only";
    EXPECT_GT(i.invocations_per_group(), 0u);
  }
  EXPECT_EQ(reflect("jfa", shaders::jfa().spirv).push_bytes, sizeof(layout::JfaParams));
  EXPECT_EQ(reflect("jfa_seed", shaders::jfa_seed().spirv).push_bytes, sizeof(layout::JfaParams));
  const ShaderInterface fim = reflect("fim", shaders::fim().spirv);
  EXPECT_EQ(fim.push_bytes, sizeof(layout::FimParams));
  // The values' windows at 0, 2, 3, 4 (split_buffer.h), the control words at 1.
  EXPECT_EQ(fim.buffers.size(), 2u + layout::VF_SPLIT_PARTS - 1);
  const ShaderInterface render = reflect("render", shaders::render().spirv);
  EXPECT_EQ(render.push_bytes, 0u);
  // Eight buffers, the arenas and the image each bound as four windows (split_buffer.h).
  ASSERT_EQ(render.buffers.size(), 8u + 3u * layout::VF_SPLIT_PARTS);
  for (std::size_t b : {5, 14, 15, 16})
    EXPECT_EQ(render.buffers[b], Access::kWrite) << "the pixels' windows are write-only: " << b;
  for (std::size_t b : {2, 3, 7, 8, 9, 10, 11, 12, 13, 17, 18, 19})
    EXPECT_EQ(render.buffers[b], Access::kRead) << "the arenas' windows are read-only: " << b;
}

TEST(GpuCompute, GeneratedGlslIsReflectedAndRefusedByName) {
  REQUIRE_GPU();
  const std::vector<std::uint32_t> spirv = compile_glsl("scale", kScale);
  const ShaderInterface i = reflect("scale", spirv);
  EXPECT_EQ(i.local_size, (std::array<std::uint32_t, 3>{32, 1, 1}));
  EXPECT_EQ(i.push_bytes, 8u);
  ASSERT_EQ(i.buffers.size(), 2u);
  EXPECT_EQ(i.buffers[0], Access::kRead);
  EXPECT_EQ(i.buffers[1], Access::kWrite);

  try {
    compile_glsl("broken", "#version 450\nlayout(local_size_x = 1) in;\nvoid main() { x = 1; }\n");
    FAIL() << "a shader that does not compile was accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("broken"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'x'"), std::string::npos) << e.what();
  }
  const std::vector<std::uint32_t> ubo = compile_glsl(
      "ubo",
      "#version 450\nlayout(local_size_x = 1) in;\nlayout(binding = 0) uniform U { float "
      "v; };\nlayout(std430, binding = 1) buffer B { float b[]; };\nvoid main() { b[0] = v; }\n");
  EXPECT_THROW(reflect("ubo", ubo), InvalidArgument);
  const std::uint32_t garbage[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  EXPECT_THROW(reflect("garbage", garbage), InvalidArgument);
}

TEST(GpuCompute, GeneratedKernelsRunAndAreCompiledOnce) {
  REQUIRE_GPU();
  auto ctx = validated();
  Context::Impl& c = ctx->impl();
  ctx->clear_validation_messages();
  const std::int64_t compiles = c.kernels.glsl_compiles();
  const Kernel& k = c.kernels.from_glsl(c.device, "scale", kScale);
  EXPECT_EQ(&c.kernels.from_glsl(c.device, "scale", kScale), &k) << "the same text is one kernel";
  EXPECT_EQ(c.kernels.glsl_compiles() - compiles, 1);

  // 1000 values: not a multiple of the local size, so the last group's tail is masked.
  const std::uint32_t n = 1000;
  Buffer host_in(c, n * 4, kUsage, true), a(c, n * 4, kUsage, false), out(c, n * 4, kUsage, false);
  Buffer host_out(c, n * 4, kUsage, true);
  auto* in = static_cast<float*>(host_in.mapped());
  std::iota(in, in + n, 0.0f);
  Recorder rec(c);
  rec.copy(host_in, 0, a, 0, n * 4);
  rec.dispatch(k, {&a, &out}, ScaleParams{0.5f, n}, n);
  rec.copy(out, 0, host_out, 0, n * 4);
  rec.submit();
  const auto* got = static_cast<const float*>(host_out.mapped());
  for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(got[i], 2.0f * static_cast<float>(i) + 0.5f) << i;
  EXPECT_THROW(rec.dispatch(k, {&a, &out}, std::uint32_t{1}, n), InvalidArgument)
      << "push constants of the wrong size";
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size() << " messages, first: " << messages.front();
}

// Recorders without an arena of their own share the context's, recycled when the last of them is
// done: a stream of submissions creates no descriptor pools, and a recorder still recording keeps
// its sets valid while another one submits.
TEST(GpuCompute, DescriptorSetsAreRecycledNotRecreated) {
  REQUIRE_GPU();
  auto ctx = validated();
  Context::Impl& c = ctx->impl();
  ctx->clear_validation_messages();
  const Kernel& k = c.kernels.from_glsl(c.device, "scale", kScale);
  const std::uint32_t n = 256;
  Buffer host(c, n * 4, kUsage, true), a(c, n * 4, kUsage, false), b(c, n * 4, kUsage, false);
  Buffer b2(c, n * 4, kUsage, false), out1(c, n * 4, kUsage, true), out2(c, n * 4, kUsage, true);
  std::iota(static_cast<float*>(host.mapped()), static_cast<float*>(host.mapped()) + n, 0.0f);
  const auto run = [&](Recorder& rec, Buffer& out, float k_add, Buffer& mid) {
    rec.copy(host, 0, a, 0, n * 4);
    rec.dispatch(k, {&a, &mid}, ScaleParams{k_add, n}, n);
    rec.copy(mid, 0, out, 0, n * 4);
  };
  const auto expect_out = [&](const Buffer& out, float k_add) {
    const auto* got = static_cast<const float*>(out.mapped());
    for (std::uint32_t i = 0; i < n; ++i)
      ASSERT_EQ(got[i], 2.0f * static_cast<float>(i) + k_add) << i;
  };
  {
    Recorder warm(c);
    run(warm, out1, 0, b);
    warm.submit();
  }
  const std::int64_t pools = ctx->counters().descriptor_pools;
  for (int i = 0; i < 20; ++i) {
    {
      Recorder rec(c);
      run(rec, out1, static_cast<float>(i), i % 2 ? b : b2);  // two sets, alternately
      rec.submit();
      expect_out(out1, static_cast<float>(i));
    }
    ASSERT_EQ(c.transient_sets->sets(), 0u) << "the last recorder's sets were recycled";
  }
  EXPECT_EQ(ctx->counters().descriptor_pools, pools) << "sets recycled, no new pools";
  {
    // Two recorders alive at once: the first, done and gone, must not recycle the second's sets
    // (a third recording would then rewrite them to its own buffers).
    std::optional<Recorder> first(std::in_place, c);
    Recorder second(c);
    run(*first, out1, 1, b);
    run(second, out2, 2, b);
    first->submit();
    first.reset();
    Recorder third(c);
    run(third, out1, 3, b2);
    second.submit();
    expect_out(out2, 2);
    third.submit();
    expect_out(out1, 3);
  }
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size() << " messages, first: " << messages.front();
}

TEST(GpuCompute, BarriersFollowTheHazardsAndNothingElse) {
  REQUIRE_GPU();
  auto ctx = validated();
  Context::Impl& c = ctx->impl();
  ctx->clear_validation_messages();
  const Kernel& scale = c.kernels.from_glsl(c.device, "scale", kScale);
  const Kernel& inc = c.kernels.from_glsl(c.device, "increment", kIncrement);
  const std::uint32_t n = 256;
  Buffer host(c, n * 4, kUsage, true), x(c, n * 4, kUsage, false), y(c, n * 4, kUsage, false),
      z(c, n * 4, kUsage, false), back_y(c, n * 4, kUsage, true), back_z(c, n * 4, kUsage, true);
  auto* h = static_cast<float*>(host.mapped());
  std::iota(h, h + n, 1.0f);

  const auto barriers = [&] { return ctx->counters().pipeline_barriers; };
  Recorder rec(c);
  std::int64_t before = barriers();
  rec.copy(host, 0, x, 0, n * 4);
  EXPECT_EQ(barriers() - before, 0) << "nothing came before the upload";
  before = barriers();
  rec.dispatch(scale, {&x, &y}, ScaleParams{0, n}, n);  // y = 2x: reads the upload
  EXPECT_EQ(barriers() - before, 1) << "read after the transfer's write";
  before = barriers();
  rec.dispatch(scale, {&x, &z}, ScaleParams{1, n}, n);  // z = 2x + 1: x already visible
  EXPECT_EQ(barriers() - before, 0) << "a second reader of x, a first writer of z";
  before = barriers();
  rec.dispatch(inc, {&y}, ScaleParams{0, n}, n);  // y += 1: after y's write
  rec.dispatch(inc, {&y}, ScaleParams{0, n}, n);  // y += 1 again
  EXPECT_EQ(barriers() - before, 2) << "each read-modify-write after the last write";
  before = barriers();
  rec.dispatch(scale, {&z, &x}, ScaleParams{0, n}, n);  // x = 2z: after x's readers and z's write
  EXPECT_EQ(barriers() - before, 1) << "write after read and read after write, one barrier";
  before = barriers();
  rec.copy(y, 0, back_y, 0, n * 4);
  rec.copy(x, 0, back_z, 0, n * 4);
  EXPECT_EQ(barriers() - before, 2);
  before = barriers();
  rec.submit();
  EXPECT_EQ(barriers() - before, 1) << "one barrier to the host for both read-backs";

  const auto* gy = static_cast<const float*>(back_y.mapped());
  const auto* gx = static_cast<const float*>(back_z.mapped());
  for (std::uint32_t i = 0; i < n; ++i) {
    const float v = static_cast<float>(i + 1);
    ASSERT_EQ(gy[i], 2 * v + 2) << i;
    ASSERT_EQ(gx[i], 2 * (2 * v + 1)) << i;
  }

  // A later submission that reads what an earlier one wrote is ordered after it.
  Recorder again(c);
  before = barriers();
  again.dispatch(inc, {&x}, ScaleParams{0, n}, n);
  EXPECT_EQ(barriers() - before, 1);
  again.copy(x, 0, back_z, 0, n * 4);
  again.submit();
  for (std::uint32_t i = 0; i < n; ++i)
    ASSERT_EQ(gx[i], 2 * (2 * static_cast<float>(i + 1) + 1) + 1) << i;

  // A recording abandoned before its submission (an exception, say) leaves no false promise: its
  // barrier made x's last write visible only in commands that never ran.
  {
    Recorder written(c);
    written.dispatch(inc, {&x}, ScaleParams{0, n}, n);
    written.submit();
  }
  {
    Recorder abandoned(c);
    abandoned.dispatch(scale, {&x, &y}, ScaleParams{0, n}, n);
  }
  Recorder after(c);
  before = barriers();
  after.dispatch(scale, {&x, &z}, ScaleParams{0, n}, n);
  EXPECT_EQ(barriers() - before, 1) << "the read of x still waits for its write";
  after.submit();
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size() << " messages, first: " << messages.front();
}

TEST(GpuCompute, GeneratedCsgKernelsEqualTheCpuTapes) {
  // The voxel compiler's generated shaders, compiled at run time and run on the device: each
  // variant's kernel, reading its cells' constants from one parameter buffer, gives at points in
  // those cells the value of the cell's pruned tape on the CPU (float against double), and the
  // interpreter running the variant's program gives the compiled kernel's values. The Menger
  // sponge is left to the CPU tests: its 20 variants take lavapipe 17 s to compile under the
  // validation layer.
  REQUIRE_GPU();
  auto ctx = validated();
  Context::Impl& c = ctx->impl();
  ctx->clear_validation_messages();
  const Kernel& interpreter =
      c.kernels.from_glsl(c.device, "interpreter", csg::glsl_interpreter_kernel());
  EXPECT_EQ(interpreter.interface.buffers.size(), 4u);
  for (const char* name : {"gear.sdf", "blobs.sdf", "building.sdf"}) {
    const csg::Model m = test::csg_example(name);
    const csg::Tape whole = csg::compile_tape(m);
    csg::OctreeOptions oo;
    oo.depth = 3;
    const csg::Octree tree = csg::build_octree(whole, m, oo);
    const csg::Bounds root = tree.root;
    const double scale =
        std::max({root.hi.x - root.lo.x, root.hi.y - root.lo.y, root.hi.z - root.lo.z, 1.0});
    std::vector<float> params;
    std::vector<std::vector<std::array<float, 4>>> points(tree.variants.size());
    std::vector<std::vector<double>> want(tree.variants.size());
    for (const csg::OctreeLeaf& l : tree.leaves) {
      if (l.state != csg::CellState::kSurface || points[l.variant].size() >= 8 * 24) continue;
      const std::uint32_t base = static_cast<std::uint32_t>(params.size());
      for (double v : tree.leaf_params(l)) params.push_back(static_cast<float>(v));
      const csg::Tape t = tree.leaf_tape(l);
      const csg::Bounds b = tree.leaf_box(l);
      for (int k = 0; k < 8; ++k) {
        const Vec3d f{k & 1 ? 0.8 : 0.2, k & 2 ? 0.7 : 0.3, k & 4 ? 0.9 : 0.4};
        const Vec3d p{b.lo.x + f.x * (b.hi.x - b.lo.x), b.lo.y + f.y * (b.hi.y - b.lo.y),
                      b.lo.z + f.z * (b.hi.z - b.lo.z)};
        float w;
        std::memcpy(&w, &base, 4);
        points[l.variant].push_back(
            {static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), w});
        // The CPU at the float point the GPU sees.
        want[l.variant].push_back(csg::evaluate(
            t, Vec3d{static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z)}));
      }
    }
    Buffer params_host(c, params.size() * 4, kUsage, true),
        params_dev(c, params.size() * 4, kUsage, false);
    std::memcpy(params_host.mapped(), params.data(), params.size() * 4);
    for (std::size_t v = 0; v < tree.variants.size(); ++v) {
      SCOPED_TRACE(std::string(name) + " variant " + std::to_string(v));
      const Kernel& k =
          c.kernels.from_glsl(c.device, "variant",
                              csg::glsl_variant_kernel(tree.variants[v].tape, static_cast<int>(v)));
      const auto n = static_cast<std::uint32_t>(points[v].size());
      ASSERT_GT(n, 0u);
      Buffer pts_host(c, n * 16, kUsage, true), pts(c, n * 16, kUsage, false),
          out(c, n * 4, kUsage, false), back(c, n * 4, kUsage, true);
      std::memcpy(pts_host.mapped(), points[v].data(), n * 16);
      // The interpreter runs the same variant from its program, at the same points.
      const std::vector<std::uint32_t> program = csg::interpreter_program(tree.variants[v].tape);
      Buffer prog_host(c, program.size() * 4, kUsage, true),
          prog(c, program.size() * 4, kUsage, false), out_i(c, n * 4, kUsage, false),
          back_i(c, n * 4, kUsage, true);
      std::memcpy(prog_host.mapped(), program.data(), program.size() * 4);
      Recorder rec(c);
      rec.copy(params_host, 0, params_dev, 0, params.size() * 4);
      rec.copy(pts_host, 0, pts, 0, n * 16);
      rec.copy(prog_host, 0, prog, 0, program.size() * 4);
      rec.dispatch(k, {&params_dev, &pts, &out}, n, n);
      rec.dispatch(interpreter, {&params_dev, &pts, &out_i, &prog}, n, n);
      rec.copy(out, 0, back, 0, n * 4);
      rec.copy(out_i, 0, back_i, 0, n * 4);
      rec.submit();
      const auto* got = static_cast<const float*>(back.mapped());
      const auto* interpreted = static_cast<const float*>(back_i.mapped());
      for (std::uint32_t i = 0; i < n; ++i) {
        ASSERT_NEAR(got[i], want[v][i], 2e-5 * scale) << "point " << i;
        // The same float operations in the same order (up to the compiler's fused multiply-adds).
        ASSERT_NEAR(interpreted[i], got[i], 1e-6 * scale) << "point " << i << ", interpreted";
      }
    }
  }
  const auto messages = ctx->validation_messages();
  EXPECT_TRUE(messages.empty()) << messages.size() << " messages, first: " << messages.front();
}
