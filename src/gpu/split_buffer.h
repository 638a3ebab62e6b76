// voxfield GPU compute layer — buffers larger than one storage-buffer binding may cover.
//
// A binding covers at most maxStorageBufferRange bytes (128 MiB on lavapipe and on some integrated
// GPUs), while a render scene's cell arenas or a large image can outgrow it. Such a buffer stays
// one VkBuffer (its copies and barriers are unchanged) and is bound as layout::VF_SPLIT_PARTS
// windows of split_part_bytes() each, which a shader reads through shaders/split_buffer.glsl.
// Parts are a power of two of bytes so the shader finds a word's part with a shift.
#pragma once

#include <array>
#include <bit>

#include "gpu/recorder.h"
#include "shaders/layout.h"

namespace voxfield::gpu {

inline constexpr int kSplitParts = static_cast<int>(layout::VF_SPLIT_PARTS);

// Bytes per window on `ctx`: the largest power of two within its storage-buffer range.
inline VkDeviceSize split_part_bytes(const Context::Impl& ctx) {
  return std::bit_floor(static_cast<VkDeviceSize>(ctx.limits.maxStorageBufferRange));
}
// log2 of the 32-bit words per window, as the shaders take it.
inline std::uint32_t split_part_shift(const Context::Impl& ctx) {
  return static_cast<std::uint32_t>(std::countr_zero(split_part_bytes(ctx) / 4));
}
// The most bytes a split buffer can hold on `ctx`.
inline VkDeviceSize split_capacity_bytes(const Context::Impl& ctx) {
  return split_part_bytes(ctx) * kSplitParts;
}

// The windows of `b`, binding by binding: part k covers bytes [k, k + 1) * split_part_bytes() of
// it; parts wholly past its end repeat part 0 (bound, never read). `b` must fit
// split_capacity_bytes().
std::array<Binding, kSplitParts> split_bindings(Buffer& b, const Context::Impl& ctx);

}  // namespace voxfield::gpu
