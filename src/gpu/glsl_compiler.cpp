// voxfield GPU compute layer — GLSL to SPIR-V at run time with glslang's C API (Debian's
// glslang-dev; its static libraries link into our shared ones, unlike Debian's libshaderc). The CSG
// compiler generates one shader per octree-cell variant; compiling them in-process avoids a glslc
// subprocess per variant and lets worker threads compile side by side.
#include <glslang/Include/glslang_c_interface.h>
#include <glslang/Public/resource_limits_c.h>

#include <memory>
#include <mutex>
#include <string>

#include "gpu/kernel.h"
#include "voxfield/error.h"
#include "voxfield/gpu.h"

namespace voxfield::gpu {

std::vector<std::uint32_t> compile_glsl(std::string_view name, std::string_view source) {
  // glslang's process-wide tables are set up once and kept for the life of the process
  // (finalising them while another thread compiles would pull them from under it).
  static std::once_flag once;
  std::call_once(once, [] { glslang_initialize_process(); });

  const std::string text(source);  // glslang wants a NUL-terminated string
  glslang_input_t in{};
  in.language = GLSLANG_SOURCE_GLSL;
  in.stage = GLSLANG_STAGE_COMPUTE;
  in.client = GLSLANG_CLIENT_VULKAN;
  in.client_version = GLSLANG_TARGET_VULKAN_1_1;
  in.target_language = GLSLANG_TARGET_SPV;
  in.target_language_version = GLSLANG_TARGET_SPV_1_3;
  in.code = text.c_str();
  in.default_version = 450;
  in.default_profile = GLSLANG_NO_PROFILE;
  in.messages =
      static_cast<glslang_messages_t>(GLSLANG_MSG_SPV_RULES_BIT | GLSLANG_MSG_VULKAN_RULES_BIT);
  in.resource = glslang_default_resource();

  const auto fail = [&](const char* stage, const char* log) {
    throw InvalidArgument("GPU shader " + std::string(name) + ": GLSL does not " + stage + ":\n" +
                          (log ? log : ""));
  };
  std::unique_ptr<glslang_shader_t, void (*)(glslang_shader_t*)> shader(glslang_shader_create(&in),
                                                                        glslang_shader_delete);
  if (!glslang_shader_preprocess(shader.get(), &in))
    fail("preprocess", glslang_shader_get_info_log(shader.get()));
  if (!glslang_shader_parse(shader.get(), &in))
    fail("compile", glslang_shader_get_info_log(shader.get()));
  std::unique_ptr<glslang_program_t, void (*)(glslang_program_t*)> program(glslang_program_create(),
                                                                           glslang_program_delete);
  glslang_program_add_shader(program.get(), shader.get());
  if (!glslang_program_link(program.get(), in.messages))
    fail("link", glslang_program_get_info_log(program.get()));
  glslang_program_SPIRV_generate(program.get(), GLSLANG_STAGE_COMPUTE);
  const std::size_t words = glslang_program_SPIRV_get_size(program.get());
  std::vector<std::uint32_t> spirv(words);
  glslang_program_SPIRV_get(program.get(), spirv.data());
  return spirv;
}

std::vector<std::uint32_t> compile_compute_shader(std::string_view name, std::string_view glsl) {
  return compile_glsl(name, glsl);
}

}  // namespace voxfield::gpu
