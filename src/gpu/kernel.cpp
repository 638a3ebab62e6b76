// voxfield GPU compute layer — kernels and their reflected interfaces (see kernel.h).
//
// Reflection uses SPIRV-Cross's C API (Debian's libspirv-cross-c-shared): the Khronos-maintained
// reader of SPIR-V that engines use for exactly this, rather than a hand-written SPIR-V walker.
#include "gpu/kernel.h"

#include <spirv_cross_c.h>

#include <algorithm>

#include "gpu/vulkan_context.h"
#include "voxfield/error.h"
#include "voxfield/hash.h"

namespace voxfield::gpu {
namespace {

struct SpvcContext {
  spvc_context ctx = nullptr;
  std::string last_error;
  SpvcContext() {
    if (spvc_context_create(&ctx) != SPVC_SUCCESS) throw InvalidArgument("SPIRV-Cross: no context");
    spvc_context_set_error_callback(
        ctx,
        [](void* user, const char* error) { static_cast<SpvcContext*>(user)->last_error = error; },
        this);
  }
  ~SpvcContext() { spvc_context_destroy(ctx); }
};

bool has_decoration(const SpvDecoration* decorations, std::size_t n, SpvDecoration d) {
  return std::find(decorations, decorations + n, d) != decorations + n;
}

}  // namespace

ShaderInterface reflect(std::string_view name, std::span<const std::uint32_t> spirv,
                        VkShaderStageFlagBits stage) {
  const std::string who = "GPU shader " + std::string(name) + ": ";
  SpvcContext c;
  spvc_parsed_ir ir = nullptr;
  spvc_compiler comp = nullptr;
  spvc_resources res = nullptr;
  if (spvc_context_parse_spirv(c.ctx, spirv.data(), spirv.size(), &ir) != SPVC_SUCCESS ||
      spvc_context_create_compiler(c.ctx, SPVC_BACKEND_NONE, ir, SPVC_CAPTURE_MODE_TAKE_OWNERSHIP,
                                   &comp) != SPVC_SUCCESS ||
      spvc_compiler_create_shader_resources(comp, &res) != SPVC_SUCCESS)
    throw InvalidArgument(who + "not a valid SPIR-V module (" + c.last_error + ")");
  const SpvExecutionModel model = spvc_compiler_get_execution_model(comp);
  const bool compute = stage == VK_SHADER_STAGE_COMPUTE_BIT;
  if (compute && model != SpvExecutionModelGLCompute)
    throw InvalidArgument(who + "not a compute shader");
  if (stage == VK_SHADER_STAGE_VERTEX_BIT && model != SpvExecutionModelVertex)
    throw InvalidArgument(who + "not a vertex shader");
  if (stage == VK_SHADER_STAGE_FRAGMENT_BIT && model != SpvExecutionModelFragment)
    throw InvalidArgument(who + "not a fragment shader");

  ShaderInterface out;
  if (compute) {
    for (int axis = 0; axis < 3; ++axis)
      out.local_size[static_cast<std::size_t>(axis)] =
          spvc_compiler_get_execution_mode_argument_by_index(comp, SpvExecutionModeLocalSize,
                                                             static_cast<unsigned>(axis));
    spvc_specialization_constant sx{}, sy{}, sz{};
    spvc_compiler_get_work_group_size_specialization_constants(comp, &sx, &sy, &sz);
    if (out.invocations_per_group() == 0 || sx.id != 0 || sy.id != 0 || sz.id != 0)
      throw InvalidArgument(who +
                            "no fixed local size (local_size_x/y/z must be literal constants, "
                            "not specialisation constants)");
  }

  const spvc_reflected_resource* list = nullptr;
  std::size_t count = 0;
  for (spvc_resource_type other :
       {SPVC_RESOURCE_TYPE_UNIFORM_BUFFER, SPVC_RESOURCE_TYPE_STORAGE_IMAGE,
        SPVC_RESOURCE_TYPE_SAMPLED_IMAGE, SPVC_RESOURCE_TYPE_SEPARATE_IMAGE,
        SPVC_RESOURCE_TYPE_SEPARATE_SAMPLERS, SPVC_RESOURCE_TYPE_ACCELERATION_STRUCTURE}) {
    spvc_resources_get_resource_list_for_type(res, other, &list, &count);
    if (count > 0)
      throw InvalidArgument(who + "declares " + list[0].name +
                            ", which is not a storage buffer (the compute layer binds storage "
                            "buffers and push constants only)");
  }

  spvc_resources_get_resource_list_for_type(res, SPVC_RESOURCE_TYPE_STORAGE_BUFFER, &list, &count);
  for (std::size_t i = 0; i < count; ++i) {
    const unsigned set = spvc_compiler_get_decoration(comp, list[i].id, SpvDecorationDescriptorSet);
    const unsigned binding = spvc_compiler_get_decoration(comp, list[i].id, SpvDecorationBinding);
    if (set != 0 || binding >= 64)
      throw InvalidArgument(who + "storage buffer " + list[i].name + " is at set " +
                            std::to_string(set) + ", binding " + std::to_string(binding) +
                            "; the compute layer binds set 0, bindings below 64");
    if (spvc_type_get_num_array_dimensions(spvc_compiler_get_type_handle(comp, list[i].type_id)) >
        0)
      throw InvalidArgument(
          who + "storage buffer " + list[i].name +
          " is an array of buffers; the compute layer binds one buffer per binding");
    if (binding >= out.buffers.size()) out.buffers.resize(binding + 1, Access::kNone);
    if (out.buffers[binding] != Access::kNone)
      throw InvalidArgument(who + "two storage buffers at binding " + std::to_string(binding));
    const SpvDecoration* decorations = nullptr;
    std::size_t n = 0;
    spvc_compiler_get_buffer_block_decorations(comp, list[i].id, &decorations, &n);
    const bool read_only = has_decoration(decorations, n, SpvDecorationNonWritable);
    const bool write_only = has_decoration(decorations, n, SpvDecorationNonReadable);
    out.buffers[binding] = read_only    ? Access::kRead
                           : write_only ? Access::kWrite
                                        : Access::kReadWrite;
  }

  spvc_resources_get_resource_list_for_type(res, SPVC_RESOURCE_TYPE_PUSH_CONSTANT, &list, &count);
  if (count > 1) throw InvalidArgument(who + "declares more than one push-constant block");
  if (count == 1) {
    std::size_t bytes = 0;
    spvc_type type = spvc_compiler_get_type_handle(comp, list[0].base_type_id);
    if (spvc_compiler_get_declared_struct_size(comp, type, &bytes) != SPVC_SUCCESS)
      throw InvalidArgument(who + "push-constant block of unknown size");
    out.push_bytes = static_cast<std::uint32_t>(bytes);
  }
  return out;
}

void make_layouts(VkDevice device, Kernel& k, VkShaderStageFlags stages) {
  const auto n = static_cast<std::uint32_t>(k.interface.buffers.size());
  std::vector<VkDescriptorSetLayoutBinding> bindings(n);
  for (std::uint32_t b = 0; b < n; ++b)
    bindings[b] = {b, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr};
  VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sl.bindingCount = n;
  sl.pBindings = bindings.data();
  check(vkCreateDescriptorSetLayout(device, &sl, nullptr, &k.set_layout),
        "vkCreateDescriptorSetLayout");
  const VkPushConstantRange push{stages, 0, k.interface.push_bytes};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &k.set_layout;
  pl.pushConstantRangeCount = push.size > 0 ? 1 : 0;
  pl.pPushConstantRanges = push.size > 0 ? &push : nullptr;
  const VkResult r = vkCreatePipelineLayout(device, &pl, nullptr, &k.layout);
  if (r != VK_SUCCESS) {
    vkDestroyDescriptorSetLayout(device, k.set_layout, nullptr);
    k.set_layout = VK_NULL_HANDLE;
    k.layout = VK_NULL_HANDLE;
    check(r, "vkCreatePipelineLayout");
  }
}

const Kernel& KernelCache::get(VkDevice device, const ShaderSource& shader) {
  const std::uint64_t key = fnv1a(kFnvOffset, shader.spirv.data(), shader.spirv.size_bytes());
  if (auto it = kernels_.find(key); it != kernels_.end()) return *it->second;

  auto k = std::make_unique<Kernel>();
  k->name = shader.name;
  k->interface = reflect(shader.name, shader.spirv);
  if (pipeline_cache_ == VK_NULL_HANDLE) {
    VkPipelineCacheCreateInfo pc{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    check(vkCreatePipelineCache(device, &pc, nullptr, &pipeline_cache_), "vkCreatePipelineCache");
  }
  struct Partial {  // destroys what was made when a later step throws
    VkDevice device;
    Kernel* k;
    ~Partial() {
      if (!k) return;
      if (k->layout) vkDestroyPipelineLayout(device, k->layout, nullptr);
      if (k->set_layout) vkDestroyDescriptorSetLayout(device, k->set_layout, nullptr);
    }
  } partial{device, k.get()};
  make_layouts(device, *k, VK_SHADER_STAGE_COMPUTE_BIT);

  VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  sm.codeSize = shader.spirv.size_bytes();
  sm.pCode = shader.spirv.data();
  VkShaderModule module;
  check(vkCreateShaderModule(device, &sm, nullptr, &module), "vkCreateShaderModule");
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module;
  info.stage.pName = "main";
  info.layout = k->layout;
  const VkResult r =
      vkCreateComputePipelines(device, pipeline_cache_, 1, &info, nullptr, &k->pipeline);
  vkDestroyShaderModule(device, module, nullptr);
  check(r, ("vkCreateComputePipelines (" + k->name + ")").c_str());
  partial.k = nullptr;
  return *kernels_.emplace(key, std::move(k)).first->second;
}

const Kernel& KernelCache::from_glsl(VkDevice device, std::string_view name,
                                     std::string_view glsl) {
  const std::uint64_t key = fnv1a(kFnvOffset, glsl.data(), glsl.size());
  if (auto it = by_glsl_.find(key); it != by_glsl_.end()) return *it->second;
  const std::vector<std::uint32_t> spirv = compile_glsl(name, glsl);
  ++glsl_compiles_;
  const std::string owned(name);
  const Kernel& k = get(device, ShaderSource{owned.c_str(), spirv});
  by_glsl_.emplace(key, &k);
  return k;
}

const Kernel* KernelCache::find_glsl(std::string_view glsl) const {
  const auto it = by_glsl_.find(fnv1a(kFnvOffset, glsl.data(), glsl.size()));
  return it == by_glsl_.end() ? nullptr : it->second;
}

const Kernel& KernelCache::adopt_glsl(VkDevice device, std::string_view name, std::string_view glsl,
                                      std::span<const std::uint32_t> spirv) {
  const std::uint64_t key = fnv1a(kFnvOffset, glsl.data(), glsl.size());
  if (auto it = by_glsl_.find(key); it != by_glsl_.end()) return *it->second;
  const std::string owned(name);
  const Kernel& k = get(device, ShaderSource{owned.c_str(), spirv});
  by_glsl_.emplace(key, &k);
  return k;
}

void KernelCache::destroy(VkDevice device) {
  for (auto& [key, k] : kernels_) {
    vkDestroyPipeline(device, k->pipeline, nullptr);
    vkDestroyPipelineLayout(device, k->layout, nullptr);
    vkDestroyDescriptorSetLayout(device, k->set_layout, nullptr);
  }
  kernels_.clear();
  by_glsl_.clear();
  if (pipeline_cache_) vkDestroyPipelineCache(device, pipeline_cache_, nullptr);
  pipeline_cache_ = VK_NULL_HANDLE;
}

}  // namespace voxfield::gpu
