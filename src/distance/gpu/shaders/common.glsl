// voxfield shaders — bindings and helpers shared by the distance passes.
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "split_buffer.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer HeaderBuf { Header h; };
layout(std430, set = 0, binding = 1) readonly buffer PageBuf { uint pages[]; };
// The world's brick pool, the resident field and its nearest sites can each outgrow one binding:
// they are bound as four windows of 2^h.part_shift words (shaders/split_buffer.glsl).
VF_SPLIT_WORDS(readonly, BrickBuf, bricks, 2, 11, 12, 13);
VF_SPLIT_LOAD(bricks, h.part_shift)
// Three cost buffers of one value per compute-box voxel (x fastest), used in turn by the passes.
layout(std430, set = 0, binding = 3) buffer Cost0 { uint cost0[]; };
layout(std430, set = 0, binding = 4) buffer Cost1 { uint cost1[]; };
layout(std430, set = 0, binding = 5) buffer Cost2 { uint cost2[]; };
// Per-line scratch of the envelope scans (Meijster's s and t arrays), one slot per voxel.
layout(std430, set = 0, binding = 6) buffer ScratchS { int scratch_s[]; };
layout(std430, set = 0, binding = 7) buffer ScratchT { int scratch_t[]; };
// The resident field: one stored value per voxel of the field's domain (x fastest).
VF_SPLIT_WORDS(, FieldBuf, field_values, 8, 14, 15, 16);  // packed (edt_encode.comp)
VF_SPLIT_LOAD(field_values, h.part_shift)
VF_SPLIT_STORE(field_values, h.part_shift)
// Nearest sites (Header::track_sites): per compute-box voxel and cost buffer, the site's
// coordinates relative to the compute box packed as (x | y << 16, z), VF_INF for none; and the
// resident field's site offsets, (dx | dy << 16, dz) as int16s, x fastest over the field's domain.
layout(std430, set = 0, binding = 9) buffer WorkSites { uvec2 work_sites[]; };
// (As words: two per voxel.)
VF_SPLIT_WORDS(, FieldSites, field_site_words, 10, 17, 18, 19);
VF_SPLIT_STORE(field_site_words, h.part_shift)

// Column neighbours (PassParams::table): per column of a table, [solid, air], each
// (below | above << 16) as int16 z offsets from its slab's first slice. Read-only but in
// edt_columns, which writes the tables.
#ifndef VF_NEIGHBOURS_ACCESS
#define VF_NEIGHBOURS_ACCESS readonly
#endif
layout(std430, set = 0, binding = 20) VF_NEIGHBOURS_ACCESS buffer Neighbours {
  uint neighbour_words[];
};

layout(push_constant) uniform Push { PassParams p; };

// Dispatches wider than the device's x limit spill into y (src/gpu/recorder.cpp: Recorder::dispatch).
uint invocation() { return gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x; }

uint load_cost(uint buffer_index, uint i) {
  if (buffer_index == 0u) return cost0[i];
  if (buffer_index == 1u) return cost1[i];
  return cost2[i];
}

void store_cost(uint buffer_index, uint i, uint value) {
  if (buffer_index == 0u) cost0[i] = value;
  else if (buffer_index == 1u) cost1[i] = value;
  else cost2[i] = value;
}

uint box_volume() { return uint(p.box_size.x * p.box_size.y * p.box_size.z); }
uvec2 load_site(uint buffer_index, uint i) { return work_sites[buffer_index * box_volume() + i]; }
void store_site(uint buffer_index, uint i, uvec2 s) { work_sites[buffer_index * box_volume() + i] = s; }
uvec2 pack_site(ivec3 l) { return uvec2(uint(l.x) | (uint(l.y) << 16), uint(l.z)); }
ivec3 unpack_site(uvec2 s) { return ivec3(int(s.x & 0xFFFFu), int(s.x >> 16), int(s.y)); }

#include "resident_world.glsl"

// Index of a compute-box voxel (coordinates relative to the box) in the cost buffers.
uint voxel_index(ivec3 l) {
  return uint((l.z * p.box_size.y + l.y) * p.box_size.x + l.x);
}

// The first voxel (local) and stride of line `line` along p.axis.
void line_of(uint line, out ivec3 first, out ivec3 step) {
  const ivec3 n = p.box_size.xyz;
  if (p.axis == 0u) {
    first = ivec3(0, int(line) % n.y, int(line) / n.y);
    step = ivec3(1, 0, 0);
  } else if (p.axis == 1u) {
    first = ivec3(int(line) % n.x, 0, int(line) / n.x);
    step = ivec3(0, 1, 0);
  } else {
    first = ivec3(int(line) % n.x, int(line) / n.x, 0);
    step = ivec3(0, 0, 1);
  }
}
