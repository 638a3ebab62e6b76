// voxfield GPU layout — the one description of GPU-side data, included by the C++ backend and by
// every GLSL shader, so both sides agree on every offset. std430 rules: 4-byte scalars, 16-byte
// vec4s; the static_asserts at the end check the C++ side.
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
struct vec4f {
  float x, y, z, w;
};
#define VF_CONST(type, name, value) constexpr type name = value
#else
#define VF_CONST(type, name, value) const type name = value
#define vec4f vec4
#endif

VF_CONST(uint, VF_UNIFORM, 0x80000000u);  // page-table entry flag: uniform chunk, value in bits 0-7
VF_CONST(uint, VF_INF, 0xFFFFFFFFu);      // "no site" in cost buffers
// Windows a buffer past one binding's range is bound as (shaders/split_buffer.glsl).
VF_CONST(uint, VF_SPLIT_PARTS, 4u);
// A slab's column neighbours (binding 20 of the exact transform): per column two words, the
// nearest solid and the nearest air voxel beyond the slab, each packed as two int16 z offsets from
// the slab's first slice (below | above << 16); this offset means "none on that side".
VF_CONST(int, VF_NO_NEIGHBOUR, -32768);

// Metrics, as in voxfield::Metric.
VF_CONST(uint, VF_MANHATTAN, 0u);
VF_CONST(uint, VF_CHEBYSHEV, 1u);
VF_CONST(uint, VF_EUCLIDEAN, 2u);
// Storage of encoded fields, as in voxfield::Storage.
// FimParams::size.w
VF_CONST(int, VF_FIM_UPDATE,
         0);  // one Jacobi pass over the region (indirect: zero groups once converged)
VF_CONST(int, VF_FIM_CONTROL,
         1);  // one invocation: count the pass, stop the next ones if nothing moved
VF_CONST(int, VF_FIM_RESOLVE, 2);  // copy the last pass's half to the first
// The FIM control words (a storage and indirect-dispatch buffer of 8 uints).
VF_CONST(uint, VF_FIM_MOVED, 0u);      // set by a pass when some voxel moved by more than eps
VF_CONST(uint, VF_FIM_LAST, 1u);       // where the last pass that ran wrote (element offset)
VF_CONST(uint, VF_FIM_PASSES, 2u);     // passes that ran
VF_CONST(uint, VF_FIM_CONVERGED, 3u);  // 1 once a pass moved nothing
VF_CONST(uint, VF_FIM_GROUPS, 4u);     // x, y, z workgroup counts of the next update pass

// RenderParams::flags
VF_CONST(uint, VF_RENDER_AO, 1u);
VF_CONST(uint, VF_RENDER_SHADOWS, 2u);
VF_CONST(uint, VF_RENDER_CHUNKS, 4u);
VF_CONST(uint, VF_RENDER_HAS_LIGHT, 8u);
VF_CONST(uint, VF_RENDER_BGRA, 16u);  // pack pixels blue first (B8G8R8A8 swapchains)
VF_CONST(uint, VF_RENDER_DISTANCE,
         32u);  // the distance view: a cut at slice_z, the field as a heat map on it
VF_CONST(uint, VF_RENDER_ERROR, 64u);  // the error view: |approximate - exact| along each ray

VF_CONST(uint, VF_U8, 0u);
VF_CONST(uint, VF_U16, 1u);
VF_CONST(uint, VF_F32, 2u);

// What stays fixed while a field lives on the GPU: where the world's chunks are, the field's
// domain, and its encoding. std430, 128 bytes, in a storage buffer. The encoding reproduces the
// CPU's exactly: the host precomputes every value that involves rounding a real number (the clamp
// and "no site" values) and the cost below which a distance is inside the clamp, so shaders only
// do integer arithmetic (and one float sqrt for f32 storage).
struct Header {
  ivec4 chunk_origin;  // chunk coordinate of page-table entry 0
  ivec4 chunk_dims;    // page-table extent in chunks; w = number of entries
  uint chunk_edge;     // voxels per chunk edge (power of two, 8..128)
  uint chunk_shift;    // log2(chunk_edge)
  uint chunk_words;    // 32-bit words per brick: chunk_edge^3 / 4
  uint track_sites;    // 1: the passes carry each voxel's nearest site, encode writes offsets
  ivec4 field_begin;   // the resident field's domain (voxel coordinates)
  ivec4 field_size;    // w: voxels per stored row (x padded to whole words of packed values)
  uint metric;         // VF_MANHATTAN...
  uint is_signed;      // 1 for signed fields
  uint storage;        // VF_U8, VF_U16, VF_F32
  uint clamp_cost;     // costs >= this are at or beyond the clamp (VF_INF: unclamped)
  uint scale_sq;       // fixed-point scale squared (integer storage of Euclidean costs)
  int bias;            // offset of signed integer storage
  uint site_cost_max;  // nearest sites: a site is kept when its cost is at most this (the clamp)
  uint part_shift;     // log2 of the words per window of the brick pool, field and sites
  uint clamp_pos;      // stored bits for +clamp, -clamp, and "no site" outside / inside
  uint clamp_neg;
  uint none_pos;
  uint none_neg;
};

// What changes from dispatch to dispatch, as push constants: 128 bytes. A pass works on a
// "compute box" (the whole domain for a full build, an edit's reach grown by the clamp for an
// update); the encode pass writes the "out box" inside it into the resident field.
//
// Column neighbours (binding 20; VF_NO_NEIGHBOUR). A box may be one z-slab of a larger problem: of
// a domain split over the processes of an MPI job (the table uploaded once, at word 0, its faces
// the field's), or of a region too large for the work buffers (tables written by edt_columns). The
// z pass then starts each column from the nearest sites beyond the slab's faces, so that its
// values are the larger problem's.
struct PassParams {
  ivec4 box_begin;  // compute box, voxel coordinates
  ivec4 box_size;
  ivec4 out_begin;  // encode: the voxels written (inside the compute box)
  ivec4 out_size;
  // The neighbour table the z pass reads: its first column (x, y), its columns per row (z) and its
  // first word in binding 20 (w); edt_columns writes its slabs' tables from word w on.
  ivec4 table;
  // The z of the slab's first slice and one past its last (x, y): the table's offsets count from
  // x, and its neighbours apply to a box reaching that face. edt_columns: the thickness of the
  // slabs it cuts the box into (z) and their count (w).
  ivec4 faces;
  uint axis;               // 0, 1, 2: the axis this pass's lines run along
  uint sites_are_air;      // 1: sites are the air voxels (the inside half of a signed field)
  uint src;                // cost buffer read by this pass (0, 1, 2)
  uint dst;                // cost buffer written by this pass
  uint src2;               // encode: the inside cost buffer of a signed field
  uint column_neighbours;  // 1: the z pass reads `table`; edt_columns: a table at word 0 (an MPI
                           // slab's) says what lies beyond the field's z faces
  uint pad1;
  uint pad2;
};

// Push constants of a jump-flooding pass: 32 bytes.
struct JfaParams {
  ivec4 size;   // the domain's extent; w: log2 of the words per window of the ping-pong buffer
  int step;     // this pass's jump, in voxels
  uint metric;  // VF_MANHATTAN...
  uint src;     // where the previous pass's sites start in the ping-pong buffer (elements)
  uint dst;     // where this pass writes
};

// Push constants of a Fast Iterative Method pass (src/distance/gpu/shaders/fim.comp): 64 bytes.
struct FimParams {
  ivec4 size;  // the domain's extent; w = mode: VF_FIM_UPDATE, VF_FIM_CONTROL, VF_FIM_RESOLVE
  ivec4 region_begin;  // the voxels the passes update (the rest only feed them); w: log2 of the
                       // words per window of the ping-pong buffer
  ivec4 region_end;
  uint src;     // where the previous pass's values start in the ping-pong buffer (elements)
  uint dst;     // where this pass writes
  uint metric;  // VF_MANHATTAN...
  float eps;    // a voxel still moving by more than this keeps the iteration going
};

// The ray marcher's frame: camera, scene layout and shading options. std430, 192 bytes, in a
// storage buffer. Per chunk of the render box, chunk_info holds 4 words: the skip arena slot (or
// VF_UNIFORM), the uniform cell (distance | material << 8) in bits 0-15 with the chunk's smallest
// distance in bits 16-23, bit 24 "no solid voxel", bit 25 "materials stored voxel by voxel"; then
// the lighting arena slot and the uniform lighting value.
struct RenderParams {
  vec4f eye;      // xyz; w = 1 for orthographic
  vec4f forward;  // the camera basis in voxels (Camera::Projector); w: its sky_scale's x,
  vec4f right;    // y and z
  vec4f up;
  vec4f sun;        // unit vector towards the sun; w = fog density
  ivec4 box_begin;  // the render box
  ivec4 box_end;
  ivec4 first_chunk;  // chunk coordinate of chunk_info entry 0; w = chunk shift
  ivec4 chunk_dims;   // chunks per axis; w = chunk voxels (edge^3)
  uint width;
  uint height;
  float scale;  // tan(fov / 2), or ortho height / 2
  uint metric;  // skip field metric (VF_MANHATTAN...)
  float skip_inv_scale;
  float light_inv_scale;
  uint flags;              // VF_RENDER_* bits
  int slice_z;             // distance view: the cut plane (voxels above it are hidden)
  uint heat_top;           // distance view: the largest stored skip distance on the cut (at
                           // least 1); the heat ramp's top is max(1, heat_top * skip_inv_scale)
  float approx_inv_scale;  // error view: stored approximate value * this = voxels
  float footprint_scale;   // Camera::Projector::footprint_scale
  uint part_shift;         // log2 of the words per window of the arenas and the image
};

// Push constants of the passes that pack a device-resident scene's cells from fields computed on
// the device (src/render/gpu/shaders/scene_pack.comp): 64 bytes. The fields are u8, over the
// render box, with the layout Header describes; the chunk table is the render box's.
VF_CONST(uint, VF_PACK_SUMMARISE, 0u);  // per listed chunk: distance and light range, solids
VF_CONST(uint, VF_PACK_WRITE, 1u);      // the listed chunks' cells into their arena slots
VF_CONST(uint, VF_PACK_HEAT, 2u);       // the distance view's RenderParams::heat_top
struct ScenePackParams {
  ivec4 first_chunk;     // chunk coordinate of chunk-table entry 0; w = chunk shift
  ivec4 chunk_dims;      // chunks per axis; w = voxels per chunk
  uint mode;             // VF_PACK_*
  uint items;            // listed chunks (summarise, write)
  uint has_light;        // 1: a lighting field is bound and packed
  int slice_z;           // heat: the cut
  uint skip_background;  // the fields' stored values outside their domain
  uint light_background;
  uint part_shift;  // log2 of the words per window of the arenas
  uint pad0;
};

// ---- vector fields (src/vectors/gpu)
// -------------------------------------------------------------- VectorParams::search: how a voxel
// finds its source.
VF_CONST(uint, VF_VECTORS_BRUTE, 0u);    // every source
VF_CONST(uint, VF_VECTORS_SPLAT, 1u);    // the sources binned to the voxel's tile
VF_CONST(uint, VF_VECTORS_WINNERS, 2u);  // read from the winners buffer (jump flooding's)
// VectorParams::flags bits.
VF_CONST(uint, VF_VECTORS_WRITE_WINNERS, 1u);  // brute / splat also store each voxel's winner
VF_CONST(int, VF_VECTORS_TILE, 8);             // splatting's bins: tiles of 8^3 voxels
// The voxel-centre table (binding 1, dvec4s): the centre, the box's three axes, its size, then the
// x, y and z offset tables (VectorParams::tables) as the CPU's CentreTables computes them.
VF_CONST(int, VF_VECTORS_TABLES, 5);

// Push constants of the vector-field passes: 96 bytes.
struct VectorParams {
  ivec4 size;    // nx, ny, nz; w = number of sources
  ivec4 tables;  // where the x, y, z offset tables start in the centre table; w unused
  ivec4 tiles;   // splatting's tiles along x, y, z; w unused
  ivec4 pass;    // x: seeding, the number of samples; flooding, the jump
  uint search;   // VF_VECTORS_BRUTE, _SPLAT or _WINNERS
  uint rule;     // 0: strongest source, 1: nearest source
  uint storage;  // 0: rgba8, 1: rgba16f, 2: rgba32f
  uint flags;    // VF_VECTORS_WRITE_WINNERS
  float decay;   // a step: decay_per_s * dt, rounded to float as the CPU's step rounds it
  uint pad0, pad1, pad2;
};

// The visualiser's view (a storage buffer): the camera and the volume's box, in floats.
struct VectorViewParams {
  vec4f centre;  // the volume's box; w unused
  vec4f size;
  vec4f axis_x;  // the box's axes in world space (rotation columns)
  vec4f axis_y;
  vec4f axis_z;
  ivec4 resolution;  // w = storage
  vec4f eye;
  vec4f dir00;  // the ray through pixel (0, 0) before normalising; xyz
  vec4f dx;     // the change per pixel to the right
  vec4f dy;     // the change per pixel down
  vec4f march;  // x: step (world units), y: density per world unit, z: max steps, w unused
  vec4f sheet;  // the reactive sheet: x 1 (drawn) or 0, y its rest height and z its push per
                // unit of vector (volume units), w unused
  ivec4 image;  // width, height; z = 1: pack pixels blue first (B8G8R8A8 swapchains); w: log2 of
                // the words per window of the image (shaders/split_buffer.glsl)
};

// ---- marching cubes on the GPU (src/mesh/gpu) ---------------------------------------------------
// The case table (binding 1, uints): per corner mask its first case and its ambiguous faces, the
// faces' corners and the cube's edges, then one record of VF_MC_CASE_WORDS per case.
VF_CONST(int, VF_MC_OFFSETS, 0);      // 256: the mask's first case
VF_CONST(int, VF_MC_AMBIGUOUS, 256);  // 256: the mask's ambiguous faces (bit per face)
VF_CONST(int, VF_MC_FACES, 512);      // 6 x 4: each face's corners in cyclic order
VF_CONST(int, VF_MC_EDGES, 536);      // 12 x 2: each edge's lower corner and axis
VF_CONST(int, VF_MC_CASES, 560);
// A case record: triangle count, 36 edge indices (12 + c: centre vertex c), centre count, two
// centre sizes, two lists of 12 edges.
VF_CONST(int, VF_MC_CASE_WORDS, 64);
VF_CONST(int, VF_MC_CENTRE, 12);
// How the samples travel (MeshParams::size.w): f32, i16 two per word, i8 four per word.
VF_CONST(int, VF_MC_F32, 0);
VF_CONST(int, VF_MC_I16, 1);
VF_CONST(int, VF_MC_I8, 2);
// MeshParams::cells.w: the HistoPyramid.
VF_CONST(int, VF_MC_PYRAMID_4, 0);      // 4-to-1 over the cells' linear order
VF_CONST(int, VF_MC_PYRAMID_8, 1);      // 8-to-1 over the cells' 3-D grid (Dyken et al. 2007)
VF_CONST(int, VF_MC_VERTEX_FLOATS, 6);  // position xyz, normal xyz

// Push constants of the marching-cubes passes: 64 bytes.
struct MeshParams {
  ivec4 size;   // samples nx, ny, nz; w = VF_MC_F32 / _I16 / _I8
  ivec4 cells;  // cells along x, y, z; w = VF_MC_PYRAMID_4 / _8
  ivec4 pass;   // x: the level a reduction builds; y: levels in all; z: triangle capacity;
                // w: the device's x limit of workgroups (the traversal strides past it)
  float iso;
  uint negate;  // 1: inside is above iso
  uint pad0, pad1;
};

// The terrain drawn by the thesis's pipeline (mesh_draw.vert / .frag): the camera as the CPU
// rasteriser's (src/render/mesh_raster.cpp) and its shading, read by both stages.
struct MeshDrawView {
  vec4f eye;      // xyz: the eye (world units); w: 1 perspective, 0 orthographic
  vec4f right;    // xyz: the camera's right; w: tan(fov / 2), or half the orthographic height
  vec4f up;       // xyz: the camera's up; w: the image's height / width
  vec4f forward;  // xyz: the viewing direction; w: the near plane's view depth (perspective)
  vec4f light;    // xyz: towards the light (unit); w: 1 colour by material, 0 the base colour
  vec4f base;     // rgb: the base colour (0..255); w unused
  vec4f depth;    // orthographic: x, y the nearest and farthest view depth of the terrain's box
};

#ifdef __cplusplus
static_assert(sizeof(MeshDrawView) == 112, "std430 size of MeshDrawView");
static_assert(sizeof(MeshParams) == 64, "push-constant size of MeshParams");
static_assert(sizeof(Header) == 128, "std430 size of Header");
static_assert(sizeof(PassParams) == 128, "push-constant size of PassParams");
static_assert(sizeof(JfaParams) == 32, "push-constant size of JfaParams");
static_assert(sizeof(FimParams) == 64, "push-constant size of FimParams");
static_assert(sizeof(RenderParams) == 192, "std430 size of RenderParams");
static_assert(sizeof(ScenePackParams) == 64, "push-constant size of ScenePackParams");
static_assert(sizeof(VectorParams) == 96, "push-constant size of VectorParams");
static_assert(sizeof(VectorViewParams) == 208, "std430 size of VectorViewParams");
}  // namespace voxfield::gpu::layout
#endif
#undef VF_CONST
#endif
