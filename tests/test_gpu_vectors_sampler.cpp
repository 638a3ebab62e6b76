// The sampler3D path of the shader sampling include (voxfield_vectors.glsl): a texture uploaded as
// a 3-D image (VectorTexture::bytes() as R8G8B8A8_UNORM, R16G16B16A16_SFLOAT or
// R32G32B32A32_SFLOAT) with linear filtering and clamp-to-edge, sampled by vf_vectors_sample at
// world points inside and outside a rotated, anisotropic volume, against the C++ sampler. The
// compute layer binds storage buffers only, so this test builds its own image, sampler and pipeline
// with Vulkan directly. Filtering hardware weighs texels with a few bits of sub-texel precision:
// each sample must be within 1/64 of the spread of its eight texels plus float rounding — and, for
// rgba8, one 8-bit step, since the filtered value may be rounded to 8 bits (lavapipe does; its
// float formats filter exactly). Lavapipe under the validation layer.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "gpu/recorder.h"
#include "gpu_suite.h"
#include "voxfield/vectors.h"

using namespace voxfield;

// A named namespace: unity builds put the GPU suites into one translation unit.
namespace sampler3d_test {

using gpu::Buffer;
using gpu::Context;

std::string kernel_text(const VectorVolume& v, VectorStorage storage) {
  std::ostringstream g;
  g.precision(17);
  auto vec = [&](Vec3d a) {
    std::ostringstream o;
    o.precision(17);
    o << "vec3(" << a.x << ", " << a.y << ", " << a.z << ")";
    return o.str();
  };
  g << "#version 450\nlayout(local_size_x = 64) in;\n"
    << "layout(set = 0, binding = 0) uniform sampler3D field;\n"
    << "layout(std430, set = 0, binding = 1) readonly buffer Points { vec4 points[]; };\n"
    << "layout(std430, set = 0, binding = 2) writeonly buffer Samples { vec4 samples[]; };\n"
    << "layout(std430, set = 0, binding = 3) writeonly buffer Inside { uint inside[]; };\n"
    << "layout(push_constant) uniform P { uint count; } p;\n"
    << test::vectors_glsl_include() << "void main() {\n"
    << "  const uint i = gl_GlobalInvocationID.x;\n"
    << "  if (i >= p.count) return;\n"
    << "  VfVectorVolume v;\n"
    << "  v.centre = " << vec(v.centre) << ";\n"
    << "  v.size = " << vec(v.size) << ";\n"
    << "  v.rotation = mat3(" << vec({v.rotation[0][0], v.rotation[1][0], v.rotation[2][0]}) << ", "
    << vec({v.rotation[0][1], v.rotation[1][1], v.rotation[2][1]}) << ", "
    << vec({v.rotation[0][2], v.rotation[1][2], v.rotation[2][2]}) << ");\n"
    << "  v.resolution = ivec3(" << v.resolution.x << ", " << v.resolution.y << ", "
    << v.resolution.z << ");\n"
    << "  v.storage = " << static_cast<int>(storage) << "u;\n"
    << "  const VfVectorSample s = vf_vectors_sample(field, v, points[i].xyz);\n"
    << "  samples[i] = vec4(s.direction, s.strength);\n"
    << "  inside[i] = s.inside ? 1u : 0u;\n"
    << "}\n";
  return g.str();
}

VkFormat format_of(VectorStorage s) {
  return s == VectorStorage::kRgba8     ? VK_FORMAT_R8G8B8A8_UNORM
         : s == VectorStorage::kRgba16f ? VK_FORMAT_R16G16B16A16_SFLOAT
                                        : VK_FORMAT_R32G32B32A32_SFLOAT;
}

// The Vulkan objects of one sampled texture, destroyed together.
struct SampledTexture {
  Context::Impl& c;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkSampler sampler = VK_NULL_HANDLE;
  explicit SampledTexture(Context::Impl& ctx) : c(ctx) {}
  ~SampledTexture() {
    vkDestroySampler(c.device, sampler, nullptr);
    vkDestroyImageView(c.device, view, nullptr);
    vkDestroyImage(c.device, image, nullptr);
    vkFreeMemory(c.device, memory, nullptr);
  }
};

void upload(SampledTexture& t, const VectorTexture& tex) {
  Context::Impl& c = t.c;
  const Vec3i n = tex.resolution();
  VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ii.imageType = VK_IMAGE_TYPE_3D;
  ii.format = format_of(tex.storage());
  ii.extent = {static_cast<std::uint32_t>(n.x), static_cast<std::uint32_t>(n.y),
               static_cast<std::uint32_t>(n.z)};
  ii.mipLevels = 1;
  ii.arrayLayers = 1;
  ii.samples = VK_SAMPLE_COUNT_1_BIT;
  ii.tiling = VK_IMAGE_TILING_OPTIMAL;
  ii.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  ASSERT_EQ(vkCreateImage(c.device, &ii, nullptr, &t.image), VK_SUCCESS);
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(c.device, t.image, &req);
  VkMemoryAllocateInfo ma{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ma.allocationSize = req.size;
  ma.memoryTypeIndex = c.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  ASSERT_EQ(vkAllocateMemory(c.device, &ma, nullptr, &t.memory), VK_SUCCESS);
  ASSERT_EQ(vkBindImageMemory(c.device, t.image, t.memory, 0), VK_SUCCESS);
  Buffer& staging = c.upload_buffer(tex.bytes().size());
  std::memcpy(staging.mapped(), tex.bytes().data(), tex.bytes().size());
  test::run_commands(c, [&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier to_dst{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    to_dst.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_dst.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    to_dst.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    to_dst.srcQueueFamilyIndex = to_dst.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_dst.image = t.image;
    to_dst.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                         0, nullptr, 0, nullptr, 1, &to_dst);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = ii.extent;
    vkCmdCopyBufferToImage(cmd, staging.handle(), t.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                           &region);
    VkImageMemoryBarrier to_read = to_dst;
    to_read.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    to_read.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    to_read.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    to_read.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                         0, 0, nullptr, 0, nullptr, 1, &to_read);
  });
  VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vi.image = t.image;
  vi.viewType = VK_IMAGE_VIEW_TYPE_3D;
  vi.format = ii.format;
  vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  ASSERT_EQ(vkCreateImageView(c.device, &vi, nullptr, &t.view), VK_SUCCESS);
  VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  si.magFilter = si.minFilter = VK_FILTER_LINEAR;
  si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
  ASSERT_EQ(vkCreateSampler(c.device, &si, nullptr, &t.sampler), VK_SUCCESS);
}

struct CountPush {
  std::uint32_t count;
};

TEST(GpuVectors, TheShaderIncludeSamplesA3dImageAsTheCppSampler) {
  if (!test::gpu_tests_wanted()) GTEST_SKIP();
  auto ctx = test::validated_context();
  Context::Impl& c = ctx->impl();
  ctx->clear_validation_messages();
  VectorVolume v;
  v.centre = {-1, 4, 2};
  v.size = {3, 5, 2};
  v.rotation = VectorVolume::rotation_about(-52, {2, -1, 1});
  v.resolution = {6, 9, 5};
  std::mt19937 rng(23);
  const std::uint32_t n = 1500;
  const auto [points, world] = test::volume_points(v, n, rng);
  constexpr VkBufferUsageFlags kUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                        VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  for (VectorStorage storage :
       {VectorStorage::kRgba8, VectorStorage::kRgba16f, VectorStorage::kRgba32f}) {
    SCOPED_TRACE(vector_storage_name(storage));
    const VectorTexture tex = test::random_vector_texture(v.resolution, storage, rng);
    SampledTexture image(c);
    upload(image, tex);
    // The pipeline: a combined image sampler and three storage buffers, one push constant.
    const std::vector<std::uint32_t> spirv =
        gpu::compile_glsl("vectors-sampler", kernel_text(v, storage));
    VkDescriptorSetLayoutBinding bindings[4]{};
    for (std::uint32_t b = 0; b < 4; ++b) {
      bindings[b].binding = b;
      bindings[b].descriptorType =
          b == 0 ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      bindings[b].descriptorCount = 1;
      bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    VkDescriptorSetLayoutCreateInfo dl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    dl.bindingCount = 4;
    dl.pBindings = bindings;
    VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateDescriptorSetLayout(c.device, &dl, nullptr, &set_layout), VK_SUCCESS);
    const VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(CountPush)};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &set_layout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &push;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreatePipelineLayout(c.device, &pl, nullptr, &layout), VK_SUCCESS);
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = spirv.size() * 4;
    sm.pCode = spirv.data();
    VkShaderModule module = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateShaderModule(c.device, &sm, nullptr, &module), VK_SUCCESS);
    VkComputePipelineCreateInfo cp{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cp.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    cp.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cp.stage.module = module;
    cp.stage.pName = "main";
    cp.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateComputePipelines(c.device, VK_NULL_HANDLE, 1, &cp, nullptr, &pipeline),
              VK_SUCCESS);
    const VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1},
                                          {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 3}};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.maxSets = 1;
    dp.poolSizeCount = 2;
    dp.pPoolSizes = sizes;
    VkDescriptorPool pool = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateDescriptorPool(c.device, &dp, nullptr, &pool), VK_SUCCESS);
    VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    da.descriptorPool = pool;
    da.descriptorSetCount = 1;
    da.pSetLayouts = &set_layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    ASSERT_EQ(vkAllocateDescriptorSets(c.device, &da, &set), VK_SUCCESS);
    Buffer pts(c, points.size() * 4, kUsage, true), samples(c, 16 * n, kUsage, true),
        inside(c, 4 * n, kUsage, true);
    std::memcpy(pts.mapped(), points.data(), points.size() * 4);
    const VkDescriptorImageInfo image_info{image.sampler, image.view,
                                           VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
    const VkDescriptorBufferInfo buffer_info[] = {{pts.handle(), 0, VK_WHOLE_SIZE},
                                                  {samples.handle(), 0, VK_WHOLE_SIZE},
                                                  {inside.handle(), 0, VK_WHOLE_SIZE}};
    VkWriteDescriptorSet writes[4]{};
    for (std::uint32_t b = 0; b < 4; ++b) {
      writes[b].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
      writes[b].dstSet = set;
      writes[b].dstBinding = b;
      writes[b].descriptorCount = 1;
      writes[b].descriptorType = bindings[b].descriptorType;
      if (b == 0)
        writes[b].pImageInfo = &image_info;
      else
        writes[b].pBufferInfo = &buffer_info[b - 1];
    }
    vkUpdateDescriptorSets(c.device, 4, writes, 0, nullptr);
    test::run_commands(c, [&](VkCommandBuffer cmd) {
      vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
      vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
      const CountPush p{n};
      vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof p, &p);
      vkCmdDispatch(cmd, (n + 63) / 64, 1, 1);
      VkMemoryBarrier to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      to_host.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
      to_host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0,
                           1, &to_host, 0, nullptr, 0, nullptr);
    });
    const auto* got = static_cast<const float*>(samples.mapped());
    const auto* in = static_cast<const std::uint32_t*>(inside.mapped());
    int checked_inside = 0, off = 0;
    for (std::uint32_t i = 0; i < n; ++i) {
      const VectorSample want = sample_vectors(v, tex, world[i]);
      ASSERT_EQ(in[i] != 0, want.inside) << "point " << i;
      if (!want.inside) {
        for (int k = 0; k < 4; ++k) EXPECT_EQ(got[4 * i + k], 0.0f);
        continue;
      }
      ++checked_inside;
      // The spread of each channel over the texels the sample filters (clamped to the volume),
      // from the same arithmetic sample_vectors uses.
      const Vec3d u = v.to_volume(world[i]);
      int lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        const double t = std::clamp(u[a] * v.resolution[a] - 0.5, 0.0, v.resolution[a] - 1.0);
        lo[a] = static_cast<int>(std::floor(t));
        hi[a] = std::min(lo[a] + 1, v.resolution[a] - 1);
      }
      double low[4] = {1e9, 1e9, 1e9, 1e9}, high[4] = {-1e9, -1e9, -1e9, -1e9};
      for (int cnr = 0; cnr < 8; ++cnr) {
        const VectorTexel t = tex.get(
            v.index(cnr & 1 ? hi[0] : lo[0], cnr & 2 ? hi[1] : lo[1], cnr & 4 ? hi[2] : lo[2]));
        const double ch[4] = {t.x, t.y, t.z, t.strength};
        for (int k = 0; k < 4; ++k) {
          low[k] = std::min(low[k], ch[k]);
          high[k] = std::max(high[k], ch[k]);
        }
      }
      const double want_ch[4] = {want.direction.x, want.direction.y, want.direction.z,
                                 want.strength};
      for (int k = 0; k < 4; ++k) {
        const double error = std::abs(got[4 * i + k] - want_ch[k]);
        const double spread = high[k] - low[k];
        // rgba8: the filtered value may itself be rounded to 8 bits (lavapipe filters UNORM8 in
        // 8-bit arithmetic): one step of 1/255, twice that for a decoded direction.
        const double quantum = storage == VectorStorage::kRgba8 ? (k < 3 ? 2.0 : 1.0) / 255 : 0.0;
        if (error > spread / 64 + quantum + 1e-5 && off++ < 5)
          ADD_FAILURE() << "point " << i << " channel " << k << ": off by " << error
                        << ", the texels spread " << spread;
      }
    }
    EXPECT_EQ(off, 0);
    EXPECT_GT(checked_inside, static_cast<int>(n) / 4);
    vkDestroyDescriptorPool(c.device, pool, nullptr);
    vkDestroyPipeline(c.device, pipeline, nullptr);
    vkDestroyShaderModule(c.device, module, nullptr);
    vkDestroyPipelineLayout(c.device, layout, nullptr);
    vkDestroyDescriptorSetLayout(c.device, set_layout, nullptr);
  }
  testing_backends::expect_no_validation_messages(Backend::kVulkan);
}

}  // namespace sampler3d_test
