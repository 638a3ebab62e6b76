// voxfield — pictures of triangle meshes on the CPU: a depth-buffered rasteriser with the same
// cameras as the voxel renderer (render.h), so a mesh and the world it came from line up pixel for
// pixel. Shading: one directional light (Lambert) plus ambient, from the vertex normals and
// colours, optionally with the triangle edges drawn (to see how a mesher tessellates).
#pragma once

#include <array>
#include <cstdint>

#include "voxfield/gpu_terrain.h"
#include "voxfield/image.h"
#include "voxfield/mesh.h"
#include "voxfield/render.h"

namespace voxfield {

struct MeshRenderOptions {
  int width = 1280, height = 720;
  Vec3d light_towards{-0.4, -0.5, 0.77};  // direction towards the light (normalised when used)
  std::array<std::uint8_t, 3> background{28, 30, 36};
  std::array<std::uint8_t, 3> base_color{200, 190, 170};  // for meshes without colours
  bool use_colors = true;
  bool edges = false;  // darken pixels within about half a pixel of a triangle edge
};

struct MeshRenderStats {
  std::size_t triangles_drawn = 0;  // in front of the camera and at least partly on screen
  std::int64_t pixels_covered = 0;
  double ms = 0;
};

// The same picture's camera and shading for the GPU terrain renderer (gpu_terrain.h).
gpu::TerrainView terrain_view(const Camera& camera, const MeshRenderOptions& options);

// Throws InvalidArgument for a size out of range (Image's limits) or a mesh whose arrays disagree.
Image render_mesh(const Mesh& mesh, const Camera& camera, const MeshRenderOptions& options,
                  MeshRenderStats* stats = nullptr);

}  // namespace voxfield
