// voxfield — a smooth, deformable terrain field: a signed scalar lattice stored per chunk in 8-bit,
// 16-bit or float samples, edited by brushes and meshed chunk by chunk (Nässén & Leiborn,
// "Real-time Terrain Deformation with Isosurface Algorithms", 2019, stored theirs as chars of
// ±100 mm on 100 mm cells; godot_voxel keeps 16 bits).
//
// The model (docs/meshing.md, "Terrain fields"):
//  * sample (x, y, z) sits at origin + (x, y, z) * spacing; its value is a signed distance in
//    world units, negative inside (positive inside when `positive_inside` is set: the thesis's
//    convention — only what value(), decode() and assign() exchange changes; brushes and meshes
//    are the same);
//  * every stored value is clamped to ±clamp: an edit then changes only samples within the clamp
//    of the brush's surface (plus its blend radius), and a chunk far from the surface holds one
//    value throughout, which is stored once (a uniform chunk costs a few bytes, not edge³ samples);
//  * i8 and i16 store round(v / step), step = clamp / 127 or clamp / 32767 (round half away from
//    zero); f32 stores the clamped float itself. Decoding gives code * step, so re-encoding an
//    unchanged sample gives its code back and samples an edit does not reach keep their bits;
//  * a material (0..255) per sample, stored the same way (uniform chunks once); meshes take their
//    vertex colours from `palette`, when set, by the material of the inside sample a vertex comes
//    from.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "voxfield/box.h"
#include "voxfield/mesh.h"
#include "voxfield/world.h"

namespace voxfield {

enum class TerrainStorage : std::uint8_t { kI8, kI16, kF32 };
const char* terrain_storage_name(TerrainStorage s);  // "i8", "i16", "f32"
// "i8", "i16", "f32"; else InvalidArgument naming the accepted ones.
TerrainStorage parse_terrain_storage(const std::string& name);

struct TerrainOptions {
  Vec3i samples{65, 65, 65};  // the lattice: each axis 2..65536
  std::array<double, 3> origin_units{0, 0, 0};
  double spacing_units = 1;  // between neighbouring samples (the thesis: 0.1 m)
  TerrainStorage storage = TerrainStorage::kI16;
  // Stored values are clamped to ±max_distance_units; 0 picks the storage's default: two samples'
  // spacing for i8 (a step of 1/63.5 of the spacing), four for i16 and f32. Normals read central
  // differences a sample from the surface, so a clamp under about two spacings bends them; a
  // larger one makes each edit reach further (an edit visits its shape's box grown by the clamp
  // and the blend radius).
  double max_distance_units = 0;
  int chunk_edge = 16;  // samples per storage chunk edge, 4..64
  bool positive_inside = false;
  std::optional<Palette> palette;  // vertex colours by material; none: meshes have no colours
};

// A brush: an analytic shape added to the terrain (union) or subtracted from it, with a sharp or
// a smooth seam. Smooth seams use the polynomial smooth minimum of radius k (Quilez, "smooth
// minimum"): smin(a, b) = min(a, b) - h^2 k / 4, h = max(k - |a - b|, 0) / k. The blend reads the
// stored (clamped) values: with k beyond the clamp, the seam's shape depends on the clamp too.
struct TerrainBrush {
  enum class Shape : std::uint8_t { kSphere, kBox, kCapsule };
  enum class Mode : std::uint8_t { kAdd, kSubtract };
  Shape shape = Shape::kSphere;
  Mode mode = Mode::kAdd;
  Vec3d centre_units;                 // sphere and box centre; the capsule's first end
  Vec3d end_units;                    // the capsule's second end
  double radius_units = 1;            // sphere and capsule
  Vec3d half_extents_units{1, 1, 1};  // box (axis-aligned)
  double smooth_units = 0;            // the blend radius k; 0: a sharp seam
  // Adding: the material of the samples where the brush is further inside than the terrain was.
  // Subtracting leaves materials alone (carving exposes what was there).
  std::uint8_t material = 1;
};

class TerrainField {
 public:
  // Every sample outside at the clamp (air) of material 0. InvalidArgument for options out of
  // range; ResourceLimitError when even its uniform chunks pass the memory limit.
  explicit TerrainField(const TerrainOptions& options);
  ~TerrainField();
  TerrainField(const TerrainField&);
  TerrainField& operator=(const TerrainField&);
  TerrainField(TerrainField&&) noexcept;
  TerrainField& operator=(TerrainField&&) noexcept;

  const TerrainOptions& options() const;  // with max_distance_units resolved
  double max_distance_units() const;
  double step_units() const;  // 0 for f32
  Vec3i size() const;
  Vec3i chunk_count() const;

  // Every sample from a function of its position (units), in the field's sign convention (a
  // height map: z - height(x, y); noise; a scan), and one material for all. Evaluated from worker
  // threads. InvalidArgument naming a sample the function gives NaN for (the first one a thread
  // meets); the field is unchanged then.
  void assign(const std::function<double(const Vec3d& position_units)>& value,
              std::uint8_t material = 0);
  // Every sample from a dense volume of this field's size (ScalarVolume's layout; its origin and
  // spacing are not used). InvalidArgument for another size or a NaN sample.
  void assign(const ScalarVolume& volume, std::uint8_t material = 0);

  // Applies a brush; returns the box of samples whose stored value or material changed (empty
  // when none): what MeshChunks::update needs. InvalidArgument for a radius that is not finite
  // and > 0 (spheres, capsules), half extents not finite and >= 0 (boxes), a non-finite position
  // or a blend radius that is not finite and >= 0; ResourceLimitError when the chunks it would
  // make dense pass the memory limit. The field is unchanged when it throws.
  Box3i apply(const TerrainBrush& brush);

  float value(Vec3i sample) const;  // decoded; InvalidArgument outside the lattice
  std::uint8_t material(Vec3i sample) const;
  // The decoded samples of `region`, x fastest, into out (region.volume() floats);
  // InvalidArgument when the region leaves the lattice.
  void decode(const Box3i& region, float* out) const;
  // The stored codes of `region` as they are kept — one byte per sample for i8, two for i16 (a
  // little-endian int16), four for f32 (the float's bits) — x fastest, always in the negative-
  // inside convention (positive_inside only flips what value() and decode() give); decoding a
  // code c gives c * step_units() (f32: the float itself). With `materials`, the samples'
  // materials too (x fastest, a byte each); `codes` may be null to read only those. For copies that
  // keep the field's width, such as the GPU renderer's uploads of the samples an edit changed
  // (gpu_terrain.h). InvalidArgument when the region leaves the lattice.
  void read_codes(const Box3i& region, void* codes, std::uint8_t* materials = nullptr) const;

  struct Memory {
    std::int64_t chunks = 0, uniform_chunks = 0;  // uniform: one value and one material
    std::uint64_t bytes = 0;                      // samples, materials and bookkeeping
  };
  Memory memory() const;

 private:
  // Every sample from value(x, y, z) (sample coordinates), built aside and swapped in.
  void assign_samples(const std::function<double(int x, int y, int z)>& value,
                      std::uint8_t material);

  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Meshes the terrain's surface (iso 0; options.iso and inside_above are ignored), in the field's
// frame, with vertex colours from the palette when the field has one. Errors as mesh_volume.
Mesh mesh_terrain(const TerrainField& terrain, const MeshOptions& options);
// mesh_terrain() written into caller-allocated arrays (mesh_bound(terrain.size(), ...) sizes
// them), as mesh_volume_into.
MeshCounts mesh_terrain_into(const TerrainField& terrain, const MeshOptions& options,
                             const MeshBuffers& out);

}  // namespace voxfield
