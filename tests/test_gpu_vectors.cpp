// The shader sampling include (include/voxfield/glsl/voxfield_vectors.glsl) against the C++
// sampler (sample_vectors): a compute shader includes it, reads a texture's texels from a storage
// buffer as the image would return them, and samples at world points inside and outside a rotated,
// anisotropic volume, in every storage. Lavapipe under the validation layer.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "gpu/recorder.h"
#include "gpu_suite.h"
#include "voxfield/vectors.h"

using namespace voxfield;
using namespace voxfield::gpu;

namespace {

// The test kernel: texels from binding 0 (as stored: rgba8 one word, rgba16f two, rgba32f four),
// points from binding 1, samples (direction, strength) to binding 2 and inside flags to binding 3.
std::string kernel_text(const VectorVolume& v, VectorStorage storage) {
  const auto f = [](double x) {
    std::ostringstream s;
    s.precision(17);
    s << x;
    return s.str();
  };
  const auto vec = [&](const Vec3d& a) {
    return "vec3(" + f(a.x) + ", " + f(a.y) + ", " + f(a.z) + ")";
  };
  const auto col = [&](int c) {
    return vec({v.rotation[0][c], v.rotation[1][c], v.rotation[2][c]});
  };
  const int words = storage == VectorStorage::kRgba8     ? 1
                    : storage == VectorStorage::kRgba16f ? 2
                                                         : 4;
  std::ostringstream g;
  g << "#version 450\nlayout(local_size_x = 64) in;\n"
    << "layout(std430, binding = 0) readonly buffer Texels { uint texels[]; };\n"
    << "layout(std430, binding = 1) readonly buffer Points { vec4 points[]; };\n"
    << "layout(std430, binding = 2) writeonly buffer Samples { vec4 samples[]; };\n"
    << "layout(std430, binding = 3) writeonly buffer Inside { uint inside[]; };\n"
    << "layout(push_constant) uniform P { uint count; } p;\n"
    << "#define VF_VECTORS_TEXEL_FETCH\n"
    << test::vectors_glsl_include() << "const ivec3 kResolution = ivec3(" << v.resolution.x << ", "
    << v.resolution.y << ", " << v.resolution.z << ");\n"
    << "vec4 vf_vectors_texel(ivec3 i) {\n"
    << "  const uint at = " << words
    << "u * uint(i.x + kResolution.x * (i.y + kResolution.y * i.z));\n";
  if (storage == VectorStorage::kRgba8)
    g << "  return unpackUnorm4x8(texels[at]);\n";
  else if (storage == VectorStorage::kRgba16f)
    g << "  return vec4(unpackHalf2x16(texels[at]), unpackHalf2x16(texels[at + 1u]));\n";
  else
    g << "  return uintBitsToFloat(uvec4(texels[at], texels[at + 1u], texels[at + 2u], texels[at + "
         "3u]));\n";
  g << "}\n"
    << "void main() {\n"
    << "  const uint i = gl_GlobalInvocationID.x;\n"
    << "  if (i >= p.count) return;\n"
    << "  VfVectorVolume v;\n"
    << "  v.centre = " << vec(v.centre) << ";\n"
    << "  v.size = " << vec(v.size) << ";\n"
    << "  v.rotation = mat3(" << col(0) << ", " << col(1) << ", " << col(2) << ");\n"
    << "  v.resolution = kResolution;\n"
    << "  v.storage = " << static_cast<int>(storage) << "u;\n"
    << "  const VfVectorSample s = vf_vectors_sample_texels(v, points[i].xyz);\n"
    << "  samples[i] = vec4(s.direction, s.strength);\n"
    << "  inside[i] = s.inside ? 1u : 0u;\n"
    << "}\n";
  return g.str();
}

struct CountPush {
  std::uint32_t count;
};

}  // namespace

TEST(GpuVectors, TheShaderIncludeSamplesAsTheCppSampler) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  Context::Impl& c = ctx->impl();
  ctx->clear_validation_messages();
  VectorVolume v;
  v.centre = {3, -2, 5};
  v.size = {4, 2.5, 1.5};
  v.rotation = VectorVolume::rotation_about(37, {1, 2, 3});
  v.resolution = {7, 5, 4};
  std::mt19937 rng(11);
  const std::uint32_t n = 2000;
  const auto [points, world] = test::volume_points(v, n, rng);
  constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  for (VectorStorage storage :
       {VectorStorage::kRgba8, VectorStorage::kRgba16f, VectorStorage::kRgba32f}) {
    const VectorTexture tex = test::random_vector_texture(v.resolution, storage, rng);
    const Kernel& k = c.kernels.from_glsl(c.device, "vectors-include", kernel_text(v, storage));
    Buffer texels(c, tex.bytes().size(), kUsage, true), pts(c, points.size() * 4, kUsage, true);
    Buffer samples(c, 16 * n, kUsage, true), inside(c, 4 * n, kUsage, true);
    std::memcpy(texels.mapped(), tex.bytes().data(), tex.bytes().size());
    std::memcpy(pts.mapped(), points.data(), points.size() * 4);
    Recorder rec(c);
    rec.dispatch(k, {&texels, &pts, &samples, &inside}, CountPush{n}, n);
    rec.submit();
    const auto* got = static_cast<const float*>(samples.mapped());
    const auto* in = static_cast<const std::uint32_t*>(inside.mapped());
    int checked_inside = 0, off = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const VectorSample want = sample_vectors(v, tex, world[i]);
      ASSERT_EQ(in[i] != 0, want.inside) << "point " << i;
      checked_inside += want.inside;
      const double e[4] = {got[4 * i] - want.direction.x, got[4 * i + 1] - want.direction.y,
                           got[4 * i + 2] - want.direction.z, got[4 * i + 3] - want.strength};
      for (double x : e)
        if (std::abs(x) > 1e-5 && off++ < 5)
          ADD_FAILURE() << "point " << i << ": a channel off by " << x;
    }
    EXPECT_EQ(off, 0);
    EXPECT_GT(checked_inside, static_cast<int>(n) / 4)
        << "a good share of the points inside the box";
  }
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}
