// voxfield — deterministic generated scenes for the showcase, tests and benchmarks.
//
// Each scene is a pure function of its options: the same options give the same voxels on every
// machine and thread count (no std:: distributions, whose output is implementation-defined).
#pragma once

#include <cstdint>
#include <string_view>

#include "voxfield/interrupt.h"
#include "voxfield/world.h"

namespace voxfield {

struct SceneOptions {
  Vec3i size{128, 128, 128};     // the world is bounded to [0, size)
  std::uint64_t seed = 6683787;  // the reference dissertation's benchmark seed
  int chunk_edge = Grid<std::uint8_t>::kDefaultChunkEdge;
};

// Rolling heightfield terrain (z up) with grass, dirt, stone and sand layers, winding caves and a
// few hollow towers with roofs standing on the surface: about half the volume is solid.
World make_terrain(const SceneOptions& options, Interrupter* interrupter = nullptr);

// Random solid spheres in an empty box, adding spheres until about `solid_fraction` of the volume
// is covered (overlaps make the true fraction slightly lower).
World make_spheres(const SceneOptions& options, double solid_fraction = 0.10,
                   Interrupter* interrupter = nullptr);

// By name: "terrain" or "spheres". Throws InvalidArgument for other names. Each generator reports
// its chunks to `interrupter` and throws Cancelled when it asks.
World make_scene(std::string_view name, const SceneOptions& options,
                 Interrupter* interrupter = nullptr);

}  // namespace voxfield
