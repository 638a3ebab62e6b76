// voxfield GPU compute layer — a compute shader as the module that owns it registers it: its name
// and its SPIR-V words. Modules list their shaders in their CMakeLists (voxfield_embed_shaders),
// which compiles each .comp with glslc and generates one function per shader returning this; the
// CSG compiler's generated GLSL becomes one through gpu::compile_glsl at run time. Nothing here
// needs the Vulkan headers, so the generated sources stay light.
#pragma once

#include <cstdint>
#include <span>

namespace voxfield::gpu {

struct ShaderSource {
  const char* name = "";
  std::span<const std::uint32_t> spirv;
};

}  // namespace voxfield::gpu
