#version 450
// voxfield — a device-resident scene's cells packed from fields that never left the device.
//
// The ray marcher (render.comp) reads per voxel a 16-bit cell (the skip field's stored distance,
// the material above it) and a lighting byte, bricked per chunk (src/render/volume.h), and per
// chunk four words of the chunk table. RenderScene makes them on the host from host fields; a
// DeviceRenderScene (device_scene.cpp) computes its fields on the device (gpu::DynamicField) and
// packs them here, from the field buffers and the world's page table and brick pool that the
// field passes read:
// - VF_PACK_SUMMARISE: one workgroup per listed chunk writes its smallest and largest stored
//   distance and lighting value and whether it holds a solid voxel — all the host needs to decide
//   which chunks are stored voxel by voxel and to write their chunk-table entries;
// - VF_PACK_WRITE: the listed chunks' cells into the slots the host gave them;
// - VF_PACK_HEAT: the largest stored distance on the distance view's cut, into the frame's
//   parameters, where render.comp reads it (RenderParams::heat_top).
// Voxels of a chunk outside the fields' domain read the fields' background, as they do from a
// host Grid, so the cells equal RenderScene's for the same fields.
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "split_buffer.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer HeaderBuf { Header h; };
layout(std430, set = 0, binding = 1) readonly buffer PageBuf { uint pages[]; };
// The world's brick pool and the fields (u8), each in four windows of 2^h.part_shift words.
VF_SPLIT_WORDS(readonly, BrickBuf, bricks, 2, 16, 17, 18);
VF_SPLIT_WORDS(readonly, SkipField, skip_values, 3, 19, 20, 21);
VF_SPLIT_WORDS(readonly, LightField, light_values, 4, 22, 23, 24);
VF_SPLIT_LOAD(bricks, h.part_shift)
VF_SPLIT_LOAD(skip_values, h.part_shift)
VF_SPLIT_LOAD(light_values, h.part_shift)
// Per listed chunk: its chunk-table index, its skip and lighting slots (VF_UNIFORM: none).
layout(std430, set = 0, binding = 5) readonly buffer Items { uvec4 items[]; };
// Per listed chunk: distance min | max << 8 | light min << 16 | light max << 24, then 1 when a
// voxel is solid.
layout(std430, set = 0, binding = 6) writeonly buffer Summaries { uvec2 summaries[]; };
layout(std430, set = 0, binding = 9) buffer ParamsBuf { RenderParams rp; };
// The arenas, each bound as four windows of 2^p.part_shift words (render.comp reads them so).
VF_SPLIT_WORDS(writeonly, SkipArena, skip_words, 7, 10, 11, 12);    // u16 per voxel
VF_SPLIT_WORDS(writeonly, LightArena, light_words, 8, 13, 14, 15);  // u8 per voxel

layout(push_constant) uniform Push { ScenePackParams p; };
VF_SPLIT_STORE(skip_words, p.part_shift)
VF_SPLIT_STORE(light_words, p.part_shift)

shared uint s_range[64];  // distance min | max << 8 | light min << 16 | light max << 24
shared uint s_solid[64];

// The stored value of voxel v (world coordinates) in a u8 field over the header's domain.
uint stored_at(bool light, ivec3 v) {
  const ivec3 f = v - h.field_begin.xyz;
  if (any(lessThan(f, ivec3(0))) || any(greaterThanEqual(f, h.field_size.xyz)))
    return light ? p.light_background : p.skip_background;
  const uint word = uint((f.z * h.field_size.y + f.y) * (h.field_size.w >> 2) + (f.x >> 2));
  const uint bits = light ? light_values(word) : skip_values(word);
  return (bits >> (uint(f.x & 3) * 8u)) & 0xFFu;
}

#include "resident_world.glsl"

// The first voxel of chunk-table entry `chunk`.
ivec3 chunk_origin(uint chunk) {
  const ivec3 d = p.chunk_dims.xyz;
  const ivec3 c = ivec3(int(chunk) % d.x, (int(chunk) / d.x) % d.y, int(chunk) / (d.x * d.y));
  return (p.first_chunk.xyz + c) << p.first_chunk.w;
}

// The voxel (relative to its chunk) at index k of the bricked layout: 4x4x4 bricks, x fastest
// inside a brick and among bricks (src/render/volume.h: ChunkTable::brick_index).
ivec3 brick_voxel(uint k) {
  const int bs = p.first_chunk.w - 2;
  const uint brick = k >> 6, m = (1u << bs) - 1u;
  const uvec3 b = uvec3(brick & m, (brick >> bs) & m, brick >> (2 * bs));
  return ivec3((b << 2) + uvec3(k & 3u, (k >> 2) & 3u, (k >> 4) & 3u));
}

uint merge(uint a, uint b) {
  const uvec4 x = uvec4(a & 0xFFu, (a >> 8) & 0xFFu, (a >> 16) & 0xFFu, a >> 24);
  const uvec4 y = uvec4(b & 0xFFu, (b >> 8) & 0xFFu, (b >> 16) & 0xFFu, b >> 24);
  return min(x.x, y.x) | (max(x.y, y.y) << 8) | (min(x.z, y.z) << 16) | (max(x.w, y.w) << 24);
}

void summarise() {
  // Workgroups stride over the items (Recorder::dispatch_strided): the loop bound is the same for
  // every invocation of a workgroup, so its barriers are reached by all.
  const uint lane = gl_LocalInvocationID.x;
  const uint volume = uint(p.chunk_dims.w), edge = 1u << p.first_chunk.w;
  for (uint item = gl_WorkGroupID.x; item < p.items; item += gl_NumWorkGroups.x) {
    const ivec3 origin = chunk_origin(items[item].x);
    uint range = 0x00FF00FFu;  // both minima 255, both maxima 0
    uint solid = 0u;
    for (uint k = lane; k < volume; k += 64u) {
      const ivec3 v = origin + ivec3(k % edge, (k / edge) % edge, k / (edge * edge));
      const uint d = stored_at(false, v);
      const uint l = p.has_light != 0u ? stored_at(true, v) : 0u;
      range = merge(range, d | (d << 8) | (l << 16) | (l << 24));
      solid |= material_at(v) != 0u ? 1u : 0u;
    }
    s_range[lane] = range;
    s_solid[lane] = solid;
    barrier();
    for (uint half_width = 32u; half_width > 0u; half_width >>= 1) {
      if (lane < half_width) {
        s_range[lane] = merge(s_range[lane], s_range[lane + half_width]);
        s_solid[lane] |= s_solid[lane + half_width];
      }
      barrier();
    }
    if (lane == 0u) summaries[item] = uvec2(s_range[0], s_solid[0]);
    barrier();  // lane 0 reads s_range[0] before the next item's first writes
  }
}

void write_cells() {
  // One invocation per four cells (one brick row along x): two words of distance cells and one
  // of lighting bytes.
  const uint quads = uint(p.chunk_dims.w) >> 2;
  const uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint i = gl_GlobalInvocationID.x; i < p.items * quads; i += stride) {
    const uvec4 item = items[i / quads];
    const uint k = (i % quads) << 2;
    const ivec3 v = chunk_origin(item.x) + brick_voxel(k);
    uint cells[4], light = 0u;
    for (int x = 0; x < 4; ++x) {
      const ivec3 w = v + ivec3(x, 0, 0);
      cells[x] = stored_at(false, w) | (material_at(w) << 8);
      if (item.z != VF_UNIFORM) light |= stored_at(true, w) << (8 * x);
    }
    if (item.y != VF_UNIFORM) {
      const uint at = (item.y * uint(p.chunk_dims.w) + k) >> 1;
      skip_words_store(at, cells[0] | (cells[1] << 16));
      skip_words_store(at + 1u, cells[2] | (cells[3] << 16));
    }
    if (item.z != VF_UNIFORM) light_words_store((item.z * uint(p.chunk_dims.w) + k) >> 2, light);
  }
}

void heat() {
  // One invocation per column of the cut.
  const uint columns = uint(h.field_size.x * h.field_size.y);
  const uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  uint top = 1u;
  for (uint i = gl_GlobalInvocationID.x; i < columns; i += stride) {
    const ivec3 f = ivec3(int(i) % h.field_size.x, int(i) / h.field_size.x, 0);
    const ivec3 v = ivec3(h.field_begin.x + f.x, h.field_begin.y + f.y, p.slice_z);
    top = max(top, stored_at(false, v));
  }
  atomicMax(rp.heat_top, top);
}

void main() {
  if (p.mode == VF_PACK_SUMMARISE) summarise();
  else if (p.mode == VF_PACK_WRITE) write_cells();
  else heat();
}
