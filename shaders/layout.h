// voxfield GPU layout — the one description of GPU-side data, included by the C++ backend and by
// every GLSL shader, so both sides agree on every offset. std430 rules: 4-byte scalars, 16-byte
// vec4s; src/gpu/layout_check.cpp asserts the C++ sizes.
//
// The world on the GPU is one pooled buffer of chunk bricks plus a page table (never a buffer or
// descriptor per chunk): the page table has one 32-bit entry per chunk of the domain's chunk grid,
// either a slot in the brick pool (a chunk stored voxel by voxel, 4 voxels per 32-bit word, x
// fastest) or, with VF_UNIFORM set, the value every voxel of the chunk holds.
#ifndef VOXFIELD_GPU_LAYOUT_H
#define VOXFIELD_GPU_LAYOUT_H

#ifdef __cplusplus
#include <cstdint>
namespace voxfield::gpu::layout {
using uint = std::uint32_t;
struct ivec4 {
  std::int32_t x, y, z, w;
};
#define VF_CONST(type, name, value) constexpr type name = value
#else
#define VF_CONST(type, name, value) const type name = value
#endif

VF_CONST(uint, VF_UNIFORM, 0x80000000u);  // page-table entry flag: uniform chunk, value in bits 0-7
VF_CONST(uint, VF_INF, 0xFFFFFFFFu);      // "no site" in cost buffers

// Metrics, as in voxfield::Metric.
VF_CONST(uint, VF_MANHATTAN, 0u);
VF_CONST(uint, VF_CHEBYSHEV, 1u);
VF_CONST(uint, VF_EUCLIDEAN, 2u);
// Storage of encoded fields, as in voxfield::Storage.
VF_CONST(uint, VF_U8, 0u);
VF_CONST(uint, VF_U16, 1u);
VF_CONST(uint, VF_F32, 2u);

VF_CONST(uint, VF_WORKGROUP, 64u);  // local_size_x of every compute shader

// Where the world's chunks are: std430, 48 bytes.
struct WorldHeader {
  ivec4 chunk_origin;  // chunk coordinate of page-table entry 0
  ivec4 chunk_dims;    // page-table extent in chunks; w = number of entries
  uint chunk_edge;     // voxels per chunk edge (power of two, 8..128)
  uint chunk_shift;    // log2(chunk_edge)
  uint chunk_words;    // 32-bit words per brick: chunk_edge^3 / 4
  uint pad0;
};

// Per-dispatch parameters of the distance passes, as push constants: 96 bytes. The encode pass
// reproduces the CPU's encoding exactly: the host precomputes every value that involves rounding
// a real number (the clamp and "no site" values) and the cost below which a distance is inside
// the clamp, so the shader only does integer arithmetic (and one float sqrt for f32 storage).
struct PassParams {
  ivec4 domain_begin;  // voxel coordinates of the domain's first voxel
  ivec4 domain_size;   // extent of the domain in voxels
  uint metric;         // VF_MANHATTAN...
  uint axis;           // 0, 1, 2: the axis this pass's lines run along
  uint sites_are_air;  // 1: sites are the air voxels (the inside half of a signed field)
  uint is_signed;      // encode: 1 for signed fields
  uint src;            // cost buffer read by this pass (0, 1, 2)
  uint dst;            // cost buffer written by this pass
  uint src2;           // encode: the inside cost buffer of a signed field
  uint pad0;
  uint clamp_cost;     // encode: costs >= this are at or beyond the clamp (VF_INF: unclamped)
  uint scale_sq;       // encode: fixed-point scale squared (integer storage of Euclidean costs)
  int bias;            // encode: offset of signed integer storage
  uint storage;        // encode: VF_U8, VF_U16, VF_F32
  uint clamp_pos;      // encode: stored bits for +clamp, -clamp, and no site outside / inside
  uint clamp_neg;
  uint none_pos;
  uint none_neg;
};

#ifdef __cplusplus
static_assert(sizeof(WorldHeader) == 48, "std430 size of WorldHeader");
static_assert(sizeof(PassParams) == 96, "push-constant size of PassParams");
}  // namespace voxfield::gpu::layout
#endif
#undef VF_CONST
#endif
