// voxfield renderer — what a RenderScene holds, shared by the tracer and the frame renderer.
//
// Everything a ray reads is copied out of the grids into bricked arenas (volume.h): a voxel read
// costs one cache line and no hash lookup, and the scene does not depend on the fields it was
// built from staying alive.
#pragma once

#include <array>
#include <optional>

#include "volume.h"
#include "voxfield/render.h"

namespace voxfield {

// Values of type T per voxel of the chunk table, bricked; chunks whose values are all equal are
// not stored. Slots are handed out densely from 0; a chunk that becomes uniform after an edit
// returns its slot to a free list, and the arena grows (by half again) when an edit makes more
// chunks dense than it holds.
template <class T>
struct BrickedChunks {
  static constexpr std::uint32_t kUniform = 0xFFFFFFFFu;
  std::vector<std::uint32_t> slot;  // per chunk: its place in the arena, or kUniform
  std::vector<T> uniform;           // per chunk: the value of a chunk not stored
  render_detail::LargeBuffer arena;
  std::uint32_t chunk_volume = 0;
  std::uint32_t slots_used = 0;           // slots ever handed out (the arena's live prefix)
  std::vector<std::uint32_t> free_slots;  // slots below slots_used no chunk holds

  std::size_t slot_bytes() const { return std::size_t{chunk_volume} * sizeof(T); }
  T* slot_data(std::uint32_t s) {
    return reinterpret_cast<T*>(arena.data()) + std::size_t{s} * chunk_volume;
  }
  // A free slot for a chunk becoming dense (the arena grows when none is left).
  std::uint32_t take_slot();

  // Where read() finds the value: lets a traversal prefetch it ahead of the read.
  const T* address(std::size_t chunk, std::uint32_t brick_index) const {
    const std::uint32_t s = slot[chunk];
    if (s == kUniform) return &uniform[chunk];
    return reinterpret_cast<const T*>(arena.data()) + static_cast<std::size_t>(s) * chunk_volume +
           brick_index;
  }
  T read(std::size_t chunk, std::uint32_t brick_index) const {
    return *address(chunk, brick_index);
  }
};

// A field rays skip by, with the materials: per voxel 16 bits, the stored distance in the low
// byte and the material in the high one, so one read tells both how far to skip and, at a hit,
// what was hit.
struct SkipSource {
  Metric metric = Metric::kManhattan;
  double inv_scale = 1;  // stored value * inv_scale = a lower bound of the distance in voxels
  BrickedChunks<std::uint16_t> cells;
  std::vector<std::uint8_t> chunk_min;  // per chunk: its smallest distance

  std::uint16_t read(std::size_t chunk, std::uint32_t brick_index) const {
    return cells.read(chunk, brick_index);
  }
  const std::uint16_t* address(std::size_t chunk, std::uint32_t brick_index) const {
    return cells.address(chunk, brick_index);
  }
  std::uint8_t distance(std::size_t chunk, std::uint32_t brick_index) const {
    return static_cast<std::uint8_t>(read(chunk, brick_index) & 0xFF);
  }
  std::uint8_t material(std::size_t chunk, std::uint32_t brick_index) const {
    return static_cast<std::uint8_t>(read(chunk, brick_index) >> 8);
  }
};

struct RenderScene::Impl {
  // Identifies this scene's contents for GPU copies: a new id whenever the scene is built, and a
  // per-chunk generation that increases whenever update() re-reads the chunk.
  std::uint64_t id = 0;
  std::uint64_t generation = 0;
  std::vector<std::uint64_t> chunk_generation;
  std::uint64_t palette_generation = 0;

  const World* world = nullptr;
  Box3i box;
  RenderSceneOptions options;
  double field_ms = 0;

  render_detail::ChunkTable table;
  SkipSource skip;
  DistanceOptions skip_options;  // of the field `skip` was made from
  bool has_light = false;
  BrickedChunks<std::uint8_t> light;  // the Euclidean lighting field
  double light_inv_scale = 0.25;
  std::vector<std::uint8_t> empty_chunk;     // 1 where a chunk holds no solid voxel
  std::vector<std::uint8_t> dense_material;  // 1 where the world stores a chunk voxel by voxel
  Palette palette{};                         // the world's palette the albedo was decoded from
  std::array<std::array<float, 3>, 256> albedo{};  // palette in linear RGB

  void build(const World& w, const DistanceField& skip_field, const DistanceField* light_field);
  // The distance view's cut plane (RenderOptions::slice_z, default the middle of the box; throws
  // InvalidArgument outside it) and the largest distance on it, which the heat map is scaled by.
  int slice_z(const RenderOptions& o) const;
  double heat_max(int slice_z) const;
  // The largest stored skip distance on the cut, at least 1 (heat_max = that * skip.inv_scale).
  std::uint32_t heat_top(int slice_z) const;
  // A skip source over this scene's table from another field (render_detail::make_skip_source).
  SkipSource make_skip_source(const DistanceField& field) const;
  // The error view's approximation: the skip field's options computed by `algorithm` (lod: FIM
  // in the middle of the box; approximation_options), as a skip source. The GPU renderer computes
  // the field on its device (bit for bit for exact and jump flooding; FIM, hybrid and lod within
  // 1e-4 voxels, so a stored step may differ) and makes it a skip source with make_skip_source.
  SkipSource approximation(Algorithm algorithm) const;
  AlgorithmOptions approximation_options(Algorithm algorithm) const;
  // Re-reads chunk i from the world and the fields (the fields already checked to fit).
  // Returns whether anything of the chunk changed.
  bool refresh_chunk(std::size_t i, const Grid<std::uint8_t>& skip_grid,
                     const Grid<std::uint8_t>* light_grid);
};

// Options of the u8 skip field: Manhattan and Chebyshev distances are integers stored as they are
// (clamp at most 255); Euclidean ones in quarter voxels (clamp at most 63); clamp 0 = the most.
// Throws InvalidArgument for a clamp out of that range.
DistanceOptions skip_field_options(const RenderSceneOptions& options, const Box3i& box);
namespace render_detail {
// What a frame checks of its options before drawing (InvalidArgument): the image size, the tile
// size, a lighting field (`has_light`) for ambient occlusion and shadows, the fog, the sun.
void check_frame_options(bool has_light, const RenderOptions& o);
// A skip source over `table` from an unsigned u8 field of `world` (cells: the field's stored
// value, the material above it), as RenderScene makes its own.
SkipSource make_skip_source(const ChunkTable& table, const World& world,
                            const DistanceField& field);
// The error view's algorithm options for a render box (lod: FIM in its middle).
AlgorithmOptions approximation_options(const Box3i& box, Algorithm algorithm);
// The error view's approximation of `world`'s skip field (`skip_options`), computed on the CPU.
SkipSource approximation(const ChunkTable& table, const World& world,
                         const DistanceOptions& skip_options, Algorithm algorithm);
}  // namespace render_detail

// Options of the u8 Euclidean lighting field (throws InvalidArgument for a clamp out of (0, 63]).
DistanceOptions light_field_options(const RenderSceneOptions& options, const Box3i& box);

}  // namespace voxfield
