// voxfield GPU compute layer — kernels: a compute pipeline made from a shader, with the descriptor
// set layout and push-constant range its own SPIR-V declares (reflected with SPIRV-Cross), so the
// C++ side never restates a binding count, a push-constant size or a workgroup size. Kernels are
// made on first use and cached by a hash of their SPIR-V (together with a VkPipelineCache); GLSL
// generated at run time is compiled by glslang and cached by a hash of its text.
//
// The interface the layer supports is deliberately small: storage buffers in set 0, at most one
// push-constant block, a fixed local size. A shader that declares anything
// else is refused by name when its kernel is made.
#pragma once

#include <volk.h>

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "gpu/shader_source.h"

namespace voxfield::gpu {

// How a shader uses a storage buffer, from its `readonly` / `writeonly` qualifiers; kNone for a
// binding it leaves out (the optimiser drops buffers a shader never touches).
enum class Access : std::uint8_t { kNone = 0, kRead = 1, kWrite = 2, kReadWrite = 3 };

struct ShaderInterface {
  std::vector<Access> buffers;  // binding b of set 0 is buffers[b], up to the last one used
  std::uint32_t push_bytes = 0;
  std::array<std::uint32_t, 3> local_size{1, 1, 1};
  std::uint32_t invocations_per_group() const {
    return local_size[0] * local_size[1] * local_size[2];
  }
};

// Reads a shader's interface from its SPIR-V: a compute shader's by default, or a vertex or
// fragment shader's (graphics.h; no local size). Throws InvalidArgument naming the shader when the
// module is malformed, is of another stage, or declares resources outside the supported interface.
ShaderInterface reflect(std::string_view name, std::span<const std::uint32_t> spirv,
                        VkShaderStageFlagBits stage = VK_SHADER_STAGE_COMPUTE_BIT);

struct Kernel;
// Makes `kernel`'s descriptor set layout (one storage buffer per binding of its interface) and its
// pipeline layout (with its push-constant range), both visible to `stages`. On a throw, what was
// made is destroyed and the handles left null.
void make_layouts(VkDevice device, Kernel& kernel, VkShaderStageFlags stages);

// Compiles a GLSL compute shader (#version 450, Vulkan rules) to SPIR-V with glslang. Thread-safe:
// generated shaders may be compiled on worker threads. Throws InvalidArgument with glslang's log
// (which names `name` and the line) when the source does not compile.
std::vector<std::uint32_t> compile_glsl(std::string_view name, std::string_view source);

struct Kernel {
  std::string name;
  ShaderInterface interface;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
};

// The kernels of one device. Not thread-safe (a Context is used by one thread at a time).
class KernelCache {
 public:
  KernelCache() = default;
  KernelCache(const KernelCache&) = delete;
  KernelCache& operator=(const KernelCache&) = delete;

  const Kernel& get(VkDevice device, const ShaderSource& shader);
  // The kernel of generated GLSL: compiled once per distinct text.
  const Kernel& from_glsl(VkDevice device, std::string_view name, std::string_view glsl);
  // The kernel of generated GLSL if it was made already (no compile), else null.
  const Kernel* find_glsl(std::string_view glsl) const;
  // The kernel of generated GLSL compiled elsewhere (on a worker thread, by compile_glsl): later
  // from_glsl and find_glsl calls with the same text find it.
  const Kernel& adopt_glsl(VkDevice device, std::string_view name, std::string_view glsl,
                           std::span<const std::uint32_t> spirv);
  std::size_t size() const { return kernels_.size(); }
  std::int64_t glsl_compiles() const { return glsl_compiles_; }
  void destroy(VkDevice device);

 private:
  std::unordered_map<std::uint64_t, std::unique_ptr<Kernel>> kernels_;  // by SPIR-V hash
  std::unordered_map<std::uint64_t, const Kernel*> by_glsl_;            // by GLSL hash
  VkPipelineCache pipeline_cache_ = VK_NULL_HANDLE;
  std::int64_t glsl_compiles_ = 0;
};

}  // namespace voxfield::gpu
