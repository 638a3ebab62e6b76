// voxfield-demo — the terrain mode: smooth hills in voxfield's terrain field (terrain.h), shaped
// with the mouse by sphere and box brushes, added or carved, sharp or smoothly blended — the loop
// of Nässén & Leiborn's thesis, with their "update only the chunks that changed" future work done.
// On a Vulkan device with marching cubes it is their pipeline: the field resident on the device,
// each edit uploading only the samples it changed, and every frame classify + HistoPyramid +
// one indirect draw through a graphics pipeline (gpu_terrain.h). Otherwise (surface nets, dual
// contouring, triangle edges, the CPU renderer, OpenGL) each edit re-meshes only the chunks it
// reaches (MeshChunks) and the CPU rasteriser draws the mesh.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fly_camera.h"
#include "voxfield/gpu_terrain_vulkan.h"
#include "voxfield/image.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/terrain.h"

namespace voxfield::demo {

struct TerrainSettings {
  int size = 128;    // samples along x and y; z holds half as many
  int storage = 0;   // i8, i16, f32
  int mesher = 0;    // mc, sn, dc
  int chunk = 16;    // cells per mesh chunk edge
  int shape = 0;     // brush: sphere, box
  float radius = 6;  // brush radius (a box's half extent), in samples
  float smooth = 3;  // blend radius; 0: sharp
  bool edges = false;
};

class TerrainMode {
 public:
  // With a context (the window's device) and marching cubes, the GPU draws; `gpu_note()` says
  // why it does not when it cannot.
  TerrainMode(const TerrainSettings& settings, std::shared_ptr<gpu::Context> context);

  // Adds (or carves) the brush where `ray` meets the surface, with `material`; false when the
  // ray misses the terrain.
  bool edit_at(const Ray& ray, bool add, std::uint8_t material);
  // A brush at the surface above (x, y) (benchmark mode's seeded edits).
  void edit_above(double x, double y, bool add, std::uint8_t material);
  // The CPU rasteriser's picture (meshing on the CPU first if only the GPU drew so far).
  Image render(const FlyCamera& camera, int width, int height);
  // On the GPU (on_gpu() only): the edits since the last frame uploaded, before the frame is
  // recorded (outside the window's frame, so a failure does not leave it half begun).
  void upload_edits();
  // The GPU's frame recorded into the window's command buffer (on_gpu() only): the buffer of its
  // pixels in `order`, for the copy into the swapchain image.
  VkBuffer record_frame(VkCommandBuffer cmd, const FlyCamera& camera, int width, int height,
                        gpu::PixelOrder order);
  bool on_gpu() const { return gpu_ != nullptr && !settings_.edges; }
  const std::string& gpu_note() const { return gpu_note_; }

  static void frame(FlyCamera& camera, const TerrainSettings& s);
  // The panel's section; returns true when the settings changed what must be rebuilt.
  static bool panel(TerrainSettings& s);
  void stats_panel() const;

  const TerrainSettings& settings() const { return settings_; }
  TerrainSettings& brush_settings() { return settings_; }  // shape, radius, smooth, edges
  std::int64_t edits() const { return edits_; }
  // The mesh's triangles: on the GPU, those its last frame drew.
  std::size_t triangles() const;
  // The last edit's re-mesh time (CPU), or the last frame's upload of its edits (GPU).
  double last_mesh_ms() const { return last_mesh_ms_; }
  // The bytes the GPU renderer uploads for an edit (the samples and materials of the box it
  // changed, in the field's width): on the GPU path, what the last frame uploaded for the edits
  // since the one before; otherwise what the last edit would upload.
  std::uint64_t last_bytes_up() const { return last_bytes_up_; }
  Box3i box() const;

 private:
  void apply(const TerrainBrush& brush);
  void mesh_on_cpu();  // (re)builds the chunked CPU mesh

  TerrainSettings settings_;
  TerrainField terrain_;
  std::unique_ptr<gpu::TerrainRenderer> gpu_;
  std::string gpu_note_;
  std::vector<Box3i> pending_;  // edits not yet uploaded to the GPU (each frame uploads them)
  std::optional<MeshChunks> chunks_;
  Mesh mesh_;
  std::int64_t edits_ = 0;
  double last_brush_ms_ = 0, last_mesh_ms_ = 0, first_mesh_ms_ = 0;
  std::uint64_t last_bytes_up_ = 0;
  std::size_t last_chunks_ = 0;
  std::string last_edit_;
};

}  // namespace voxfield::demo
