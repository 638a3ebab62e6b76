// voxfield — World: materials on a sparse grid plus a 256-entry RGBA palette (the MagicaVoxel
// model, so .vox files map directly).
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "voxfield/grid.h"
#include "voxfield/voxel_frame.h"

namespace voxfield {

struct Rgba {
  std::uint8_t r = 0, g = 0, b = 0, a = 0;
  friend constexpr bool operator==(const Rgba&, const Rgba&) = default;
};

// palette[m] is the colour of material m; palette[0] belongs to air and is never drawn.
using Palette = std::array<Rgba, 256>;

// MagicaVoxel's built-in palette, used by .vox files that carry no RGBA chunk. It is generated,
// not tabulated: a 6x6x6 colour cube (channel levels FF, CC, 99, 66, 33, 00; red slowest, blue
// fastest; black left out) in entries 1..215, then ten-step ramps of red, green, blue and grey
// (levels EE DD BB AA 88 77 55 44 22 11, the ones the cube lacks) in 216..255.
Palette default_palette();

struct World {
  // Material per voxel; 0 = air (the background).
  Grid<std::uint8_t> voxels;
  Palette palette = default_palette();
  // Where the voxels sit in the world (voxel_frame.h); the identity unless given — by a .vdb's
  // transform, a voxelised mesh's voxel size, a .vfw that stored one, or the caller.
  VoxelFrame frame;

  explicit World(int chunk_edge = Grid<std::uint8_t>::kDefaultChunkEdge,
                 std::optional<Box3i> bounds = std::nullopt)
      : voxels(chunk_edge, 0, bounds) {}

  // Number of non-air voxels.
  std::int64_t solid_count() const { return voxels.count_non_background(); }
  // How many voxels hold each material (index 0 counts air only inside stored chunks).
  std::array<std::int64_t, 256> material_histogram() const;
};

}  // namespace voxfield
