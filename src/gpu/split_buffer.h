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
#include <string>

#include "gpu/recorder.h"
#include "shaders/layout.h"

namespace voxfield::gpu {

inline constexpr int kSplitParts = static_cast<int>(layout::VF_SPLIT_PARTS);

// Bytes per window on `ctx`: the largest power of two within its storage-buffer range (at least
// its offset alignment, a power of two no larger: Context::Impl::cap_storage_buffer_range), and
// at most 1 GiB, so that four windows, 4 GiB, index every byte with the shaders' 32-bit uints.
inline VkDeviceSize split_part_bytes(const Context::Impl& ctx) {
  return std::min<VkDeviceSize>(
      std::bit_floor(static_cast<VkDeviceSize>(ctx.limits.maxStorageBufferRange)),
      VkDeviceSize{1} << 30);
}
// log2 of the 32-bit words per window, as the shaders take it.
inline std::uint32_t split_part_shift(const Context::Impl& ctx) {
  return static_cast<std::uint32_t>(std::countr_zero(split_part_bytes(ctx) / 4));
}
// The most bytes a split buffer can hold on `ctx`.
inline VkDeviceSize split_capacity_bytes(const Context::Impl& ctx) {
  return split_part_bytes(ctx) * kSplitParts;
}

// Refuses (InvalidArgument: "<what> needs <bytes> bytes, more than this device binds (...)") a
// buffer bound in windows that four cannot hold.
void check_split_binding(const Context::Impl& ctx, VkDeviceSize bytes, const std::string& what);

// Refuses (InvalidArgument naming `what` and the sizes) a buffer of `bytes` that is bound whole
// but would not fit one binding: a host scene's chunk table, which only a box of millions of
// chunks outgrows (other per-chunk tables are smaller than a field their module checks first).
void check_whole_binding(const Context::Impl& ctx, VkDeviceSize bytes, const std::string& what);

// The windows of `b`, binding by binding: part k covers bytes [k, k + 1) * split_part_bytes() of
// it; parts wholly past its end repeat part 0 (bound, never read). `b` must fit
// split_capacity_bytes().
std::array<Binding, kSplitParts> split_bindings(Buffer& b, const Context::Impl& ctx);

}  // namespace voxfield::gpu
