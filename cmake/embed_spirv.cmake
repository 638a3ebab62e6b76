# Wraps a SPIR-V module, as glslc writes it with -mfmt=num (the 32-bit words as comma-separated hex
# numbers), in a C++ source defining the shader's gpu::ShaderSource (src/gpu/shader_source.h), so
# the shaders travel inside the library (no files to find at run time). glslc does the byte-to-word
# work; this script only checks the text and wraps it, in time linear in its size (a CMake loop
# over the bytes took a minute for the 108 KB ray marcher).
# cmake -DIN=x.spv.num -DOUT=x_spv.cpp -DNAME=x -P embed_spirv.cmake
file(READ "${IN}" words)
string(STRIP "${words}" words)
if(NOT words MATCHES "^0x07230203")
  message(FATAL_ERROR "${IN}: not a SPIR-V module in glslc's -mfmt=num form (no magic number first)")
endif()
file(WRITE "${OUT}.tmp" "// Generated from ${IN} by cmake/embed_spirv.cmake. Do not edit.\n#include \"gpu/shader_source.h\"\nnamespace voxfield::gpu::shaders {\nnamespace {\nconst std::uint32_t k_${NAME}_words[] = {\n${words}};\n}\nShaderSource ${NAME}() { return {\"${NAME}\", k_${NAME}_words}; }\n}  // namespace voxfield::gpu::shaders\n")
file(RENAME "${OUT}.tmp" "${OUT}")
