// voxfield — a terrain field drawn on the GPU the reference thesis's way (Nässén & Leiborn,
// "Real-time Terrain Deformation with Isosurface Algorithms", 2019, after Dyken, Ziegler, Theobalt
// & Seidel, "High-speed Marching Cubes using HistoPyramids", 2007): the field stays on the device
// in its own width (i8 four samples per word, i16 two, f32), and every frame runs marching cubes'
// classify pass and HistoPyramid (gpu_mesh.h) and then one vkCmdDrawIndirect whose vertex count
// the pyramid's top wrote — no vertex buffer: the vertex shader walks the pyramid by
// gl_VertexIndex to its cell and triangle and computes the CPU marching cubes' vertex. Nothing is
// read back to draw a frame. After an edit only the samples it changed are uploaded (the thesis
// re-sent the whole field every frame and named this as future work).
//
// The picture is the CPU rasteriser's (render_mesh, mesh_render.h) of mesh_terrain()'s mesh:
// the same camera, one directional light plus ambient, both faces lit, vertex colours from the
// palette by the material of the inside sample a vertex comes from — equal up to rasterisation
// rules on triangle edges (tests/test_gpu_terrain.cpp states the tolerance).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/gpu.h"
#include "voxfield/gpu_mesh.h"
#include "voxfield/image.h"
#include "voxfield/terrain.h"

namespace voxfield::gpu {

// Where the terrain is seen from and how it is lit: a camera's orthonormal basis and the CPU
// rasteriser's shading options. terrain_view() (mesh_render.h) makes one from a Camera and
// MeshRenderOptions, so a GPU frame and render_mesh() of the same camera line up pixel for pixel.
struct TerrainView {
  int width = 1280, height = 720;
  bool perspective = true;  // else orthographic
  Vec3d eye{0, 0, 0}, forward{0, 0, -1}, right{1, 0, 0}, up{0, 1, 0};
  double scale = 1;  // tan(vertical fov / 2), or half the orthographic height in world units
  Vec3d light_towards{-0.4, -0.5, 0.77};  // towards the light (normalised when used)
  std::array<std::uint8_t, 3> background{28, 30, 36};
  std::array<std::uint8_t, 3> base_color{200, 190, 170};  // without colours or a palette
  bool use_colors = true;
};

// Hardware-independent figures of one frame (render()) or one sync.
struct TerrainDrawStats {
  std::int64_t dispatches = 0, draws = 0, submits = 0, fence_waits = 0;
  std::int64_t bytes_uploaded = 0, bytes_downloaded = 0;
  std::uint64_t triangles = 0;  // drawn (render(): read from the draw's arguments afterwards)
  int pyramid_levels = 0;
  double ms = 0;  // wall time of the call (on lavapipe: CPU emulation)
  // render(): the passes' GPU times from timestamps — classify, HistoPyramid, draw (on lavapipe:
  // CPU emulation, not GPU speed); empty where the queue has no timestamps.
  std::vector<PassTiming> passes;
};

// Not thread-safe; one frame at a time (a frame's buffers are reused by the next).
class TerrainRenderer {
 public:
  // InvalidArgument without a context; GpuUnavailable without shaderFloat64 (the vertices are
  // computed in doubles, as the CPU's).
  explicit TerrainRenderer(std::shared_ptr<Context> context, Pyramid pyramid = Pyramid::kFourToOne);
  ~TerrainRenderer();
  TerrainRenderer(const TerrainRenderer&) = delete;
  TerrainRenderer& operator=(const TerrainRenderer&) = delete;

  // Copies the whole field (samples, materials, palette) to the device: the first time, and
  // whenever the terrain's size, storage, frame or palette differs from the resident copy. A copy
  // that replaces the device's buffers first waits for the queue to be idle (a frame recorded
  // earlier may still read them). Returns the bytes uploaded. ResourceLimitError when the
  // samples or the pyramid pass one storage buffer of the device.
  std::uint64_t sync(const TerrainField& terrain);
  // After TerrainField::apply: copies only the samples (and materials) in `changed`, the box
  // apply() returned — each of its rows in the field's own width — or everything when the
  // resident copy is not of this terrain's shape (as sync(terrain)). Empty: nothing. One submit
  // when anything is copied. InvalidArgument for a box outside the lattice.
  std::uint64_t sync(const TerrainField& terrain, const Box3i& changed);
  // The boxes of several edits (a frame's), in one submit: overlapping boxes are merged first, so
  // no sample is sent twice.
  std::uint64_t sync(const TerrainField& terrain, std::span<const Box3i> changed);

  // A frame of the synced terrain, read back: classify, the pyramid, the draw's arguments, the
  // draw and the copy of its pixels in one submit. Without use_colors, or for a terrain without a
  // palette, the surface is view.base_color. Throws InvalidArgument before the first sync and for
  // a size out of range or past the device's framebuffer limits.
  Image render(const TerrainView& view, TerrainDrawStats* stats = nullptr);

  // The triangles the last frame drew (render(), or record_render() once its commands completed:
  // gpu_terrain_vulkan.h), read from the draw's arguments in host-visible memory.
  std::uint64_t last_triangles() const;
  Context& context();
  struct Impl;
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxfield::gpu
