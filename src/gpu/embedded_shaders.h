// voxfield GPU backend — the compute shaders, compiled to SPIR-V by glslc at build time and
// embedded by cmake/embed_spirv.cmake (sources in shaders/).
#pragma once

#include <cstdint>
#include <span>

namespace voxfield::gpu::shaders {

std::span<const std::uint32_t> edt_sites();
std::span<const std::uint32_t> edt_lines();
std::span<const std::uint32_t> edt_encode();
std::span<const std::uint32_t> render();
std::span<const std::uint32_t> jfa();
std::span<const std::uint32_t> jfa_seed();
std::span<const std::uint32_t> fim();

}  // namespace voxfield::gpu::shaders
