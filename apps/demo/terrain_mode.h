// voxfield-demo — the terrain mode: smooth hills in voxfield's terrain field (terrain.h), shaped
// with the mouse by sphere and box brushes, added or carved, sharp or smoothly blended, each edit
// re-meshing only the chunks it reaches (MeshChunks) — the loop of Nässén & Leiborn's thesis, with
// their "update only the chunks that changed" future work done. The mesh is drawn by voxfield's
// CPU rasteriser and presented like the CPU renderer's frames (the Vulkan graphics pipeline of the
// meshing issue is not built yet).
#pragma once

#include <optional>
#include <string>

#include "fly_camera.h"
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
  explicit TerrainMode(const TerrainSettings& settings);

  // Adds (or carves) the brush where `ray` meets the surface, with `material`; false when the
  // ray misses the terrain.
  bool edit_at(const Ray& ray, bool add, std::uint8_t material);
  // A brush at the surface above (x, y) (benchmark mode's seeded edits).
  void edit_above(double x, double y, bool add, std::uint8_t material);
  Image render(const FlyCamera& camera, int width, int height) const;

  static void frame(FlyCamera& camera, const TerrainSettings& s);
  // The panel's section; returns true when the settings changed what must be rebuilt.
  static bool panel(TerrainSettings& s);
  void stats_panel() const;

  const TerrainSettings& settings() const { return settings_; }
  TerrainSettings& brush_settings() { return settings_; }  // shape, radius, smooth, edges
  std::int64_t edits() const { return edits_; }
  std::size_t triangles() const { return mesh_.triangle_count(); }
  double last_mesh_ms() const { return last_mesh_ms_; }
  // Bytes a renderer keeping the field on the GPU would upload for the last edit, at most: the
  // storage chunks its changed box meets, whole.
  std::uint64_t last_bytes_up() const { return last_bytes_up_; }
  Box3i box() const;

 private:
  void apply(const TerrainBrush& brush);

  TerrainSettings settings_;
  TerrainField terrain_;
  std::optional<MeshChunks> chunks_;
  Mesh mesh_;
  std::int64_t edits_ = 0;
  double last_brush_ms_ = 0, last_mesh_ms_ = 0, first_mesh_ms_ = 0;
  std::uint64_t last_bytes_up_ = 0;
  std::size_t last_chunks_ = 0;
  std::string last_edit_;
};

}  // namespace voxfield::demo
