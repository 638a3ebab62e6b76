// voxfield GPU compute layer — what a build without the Vulkan backend answers. Part of the layer's
// internal interface: the modules' GPU halves (src/distance/gpu, src/render/gpu) compile their
// no-Vulkan entry points against it.
#pragma once

namespace voxfield::gpu {

// Throws GpuUnavailable saying this build has no Vulkan backend.
[[noreturn]] void built_without_vulkan();

}  // namespace voxfield::gpu
