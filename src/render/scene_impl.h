// voxfield renderer — what a RenderScene holds, shared by the tracer and the frame renderer.
#pragma once

#include <array>
#include <optional>

#include "volume.h"
#include "voxfield/render.h"

namespace voxfield {

// A field rays skip by, copied with the materials out of their grids into one arena of bricked
// chunks (volume.h): per voxel 16 bits, the stored distance in the low byte and the material in the
// high one, so a ray's read costs one cache line, no hash lookup, and tells both how far to skip
// and, at a hit, what was hit. Chunks where both are uniform are not stored.
struct SkipSource {
  Metric metric = Metric::kManhattan;
  double inv_scale = 1;  // stored value * inv_scale = a lower bound of the distance in voxels
  static constexpr std::uint32_t kUniform = 0xFFFFFFFFu;
  std::vector<std::uint32_t> slot;        // per chunk: its place in the arena, or kUniform
  std::vector<std::uint8_t> chunk_min;    // per chunk: its smallest distance (the value, if uniform)
  std::vector<std::uint8_t> chunk_material;  // per uniform chunk: its material
  render_detail::LargeBuffer arena;       // u16 per voxel
  std::uint32_t chunk_volume = 0;

  // Distance (low byte) and material (high byte) of a voxel.
  std::uint16_t read(std::size_t chunk, std::uint32_t brick_index) const {
    const std::uint32_t s = slot[chunk];
    if (s == kUniform) return static_cast<std::uint16_t>(chunk_min[chunk] | (chunk_material[chunk] << 8));
    return reinterpret_cast<const std::uint16_t*>(arena.data())[static_cast<std::size_t>(s) * chunk_volume + brick_index];
  }
  std::uint8_t distance(std::size_t chunk, std::uint32_t brick_index) const {
    return static_cast<std::uint8_t>(read(chunk, brick_index) & 0xFF);
  }
};

struct RenderScene::Impl {
  const World* world = nullptr;
  Box3i box;
  RenderSceneOptions options;
  DistanceField skip_field;
  std::optional<DistanceField> light_field;
  double field_ms = 0;

  render_detail::ChunkTable table;
  render_detail::VoxelLayer material;
  render_detail::VoxelLayer light;  // empty vectors without a lighting field
  double light_inv_scale = 0.25;
  SkipSource skip;
  std::vector<std::uint8_t> empty_chunk;  // 1 where a chunk of the table holds no solid voxel
  std::array<std::array<float, 3>, 256> albedo{};  // palette in linear RGB

  SkipSource make_skip_source(const DistanceField& field) const;
};

// Options of the u8 skip field for a metric: Manhattan and Chebyshev distances are integers
// stored as they are (clamp 255); Euclidean ones in quarter voxels (clamp 63).
DistanceOptions skip_field_options(Metric metric, const Box3i& box);

}  // namespace voxfield
