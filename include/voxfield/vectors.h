// voxfield — dynamic vector-field volume textures (docs/vectors.md).
//
// After Hamlin, "Volumetric Interaction: Real-Time Dynamic Volume Textures" (UTS): moving sources
// (a position, the previous position and a radius each) push the space around them; a volume
// texture holds, at every voxel, the direction away from the strongest source that reaches it and
// that strength. Each fixed time step generates a new texture, decays the previous one's strength
// and blends the two, so moving sources leave fading wakes that grass, water and particles react
// to.
//
// One model, used by every algorithm, the sampler and the files:
//  * a VectorVolume is an oriented box in world space with a resolution; voxel (i, j, k) has its
//    centre at volume coordinates ((i + 1/2) / nx, (j + 1/2) / ny, (k + 1/2) / nz);
//  * a source covers the segment from its previous to its current position with radius r; at a
//    voxel centre p its distance d is that to the nearest point q of the segment, its strength
//    s = 1 - d / r where d < r;
//  * the field at p: the covering source of greatest s (ties: the lower index) gives the direction
//    (p - q) / |p - q| — away from the source, 0 where d = 0 — and the strength s. No source:
//    direction 0, strength 0. VectorRule::kNearest takes the nearest covering source instead.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/image.h"

namespace voxfield {

class Interrupter;

// An oriented box in world space and its resolution.
struct VectorVolume {
  Vec3d centre{0, 0, 0};
  Vec3d size{1, 1, 1};  // full extents along the box's own axes, world units
  // Rows of the rotation from the box's axes to world space: world = centre + R * local.
  std::array<Vec3d, 3> rotation{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  Vec3i resolution{64, 64, 64};

  // Rotation by `degrees` about `axis` (voxfield::rotation_about in voxel_frame.h; throws
  // InvalidArgument for a zero axis).
  static std::array<Vec3d, 3> rotation_about(double degrees, Vec3d axis);

  std::int64_t voxel_count() const;
  std::int64_t index(int i, int j, int k) const {
    return i + static_cast<std::int64_t>(resolution.x) *
                   (j + static_cast<std::int64_t>(resolution.y) * k);
  }
  // World position of voxel (i, j, k)'s centre.
  Vec3d voxel_centre(int i, int j, int k) const;
  // Volume coordinates of a world point: [0, 1]^3 inside the box.
  Vec3d to_volume(Vec3d world) const;
  // World point of volume coordinates u.
  Vec3d to_world(Vec3d u) const;
  // Edge of one voxel along each of the box's axes, world units.
  Vec3d voxel_size() const;
  // Throws InvalidArgument naming the field: a non-finite or non-positive size, a resolution
  // outside 1..4096 per axis, a rotation that is not orthonormal, non-finite centre.
  void validate() const;
};

struct VectorSource {
  Vec3d position;
  Vec3d previous;  // where it was one step ago (equal to position for a stationary source)
  double radius = 1;
};

// Throws InvalidArgument naming the source's index: a radius that is not finite and positive,
// a non-finite position.
void validate_sources(std::span<const VectorSource> sources);

enum class VectorRule { kStrongest, kNearest };
enum class VectorAlgorithm { kBrute, kSplat, kJfa, kJfaPlus1, kJfaPlus2 };
enum class VectorStorage { kRgba8, kRgba16f, kRgba32f };

const char* vector_rule_name(VectorRule r);             // "strongest", "nearest"
const char* vector_algorithm_name(VectorAlgorithm a);   // "brute", "splat", "jfa", "jfa+1", "jfa+2"
const char* vector_storage_name(VectorStorage s);       // "rgba8", "rgba16f", "rgba32f"
VectorRule parse_vector_rule(const std::string& name);  // InvalidArgument for anything else
VectorAlgorithm parse_vector_algorithm(const std::string& name);
VectorStorage parse_vector_storage(const std::string& name);

// One decoded texel: a world-space direction (unit or zero) and a strength in [0, 1].
struct VectorTexel {
  float x = 0, y = 0, z = 0, strength = 0;
  friend bool operator==(const VectorTexel&, const VectorTexel&) = default;
};

// A volume texture: four channels per voxel, x fastest, in one of three storages.
//  * rgba8: each direction component c stored as floor((c + 1) / 2 * 255 + 1/2), the strength as
//    floor(s * 255 + 1/2); decoded as 2 * byte / 255 - 1 and byte / 255 (a zero texel is
//    128, 128, 128, 0, as the paper's);
//  * rgba16f: IEEE half floats, rounded to nearest even; rgba32f: floats.
class VectorTexture {
 public:
  VectorTexture() = default;
  // A zero texture. Throws InvalidArgument for a resolution outside 1..4096 per axis,
  // ResourceLimitError past the memory limit (limits.h).
  VectorTexture(Vec3i resolution, VectorStorage storage);

  Vec3i resolution() const { return resolution_; }
  VectorStorage storage() const { return storage_; }
  std::int64_t voxel_count() const { return Box3i::from_size(resolution_).volume(); }
  int bytes_per_texel() const;
  // The raw texels, x fastest, as a GPU upload takes them (layout in docs/vectors.md).
  std::span<const std::uint8_t> bytes() const { return bytes_; }
  std::uint8_t* data() { return bytes_.data(); }

  VectorTexel get(std::int64_t index) const;
  void set(std::int64_t index, const VectorTexel& texel);
  // The texel as stored would decode: encode then decode (rgba8 and rgba16f round).
  static VectorTexel quantize(const VectorTexel& texel, VectorStorage storage);
  void clear();

 private:
  Vec3i resolution_;
  VectorStorage storage_ = VectorStorage::kRgba8;
  std::vector<std::uint8_t> bytes_;
};

// The exact field at world point p (double precision; the oracle of every algorithm).
struct VectorValue {
  Vec3d direction;  // unit or zero
  double strength = 0;
  int source = -1;  // the winning source, -1 for none
};
VectorValue vector_at(Vec3d p, std::span<const VectorSource> sources, VectorRule rule);

struct VectorOptions {
  VectorAlgorithm algorithm = VectorAlgorithm::kSplat;
  VectorRule rule = VectorRule::kStrongest;
  Interrupter* interrupter = nullptr;  // asked between slabs; never kept
};

// Milliseconds spent in each pass of a generation or a step.
struct VectorPassTimes {
  double seed_ms = 0;     // jfa*: marking the voxels the sources touch
  double flood_ms = 0;    // jfa*: the passes of step N/2 ... 1 (and the extra ones)
  double search_ms = 0;   // brute / splat: finding each voxel's source
  double convert_ms = 0;  // directions and strengths from the winners, into the texture
  double decay_ms = 0;    // a step: the previous texture's strength decayed
  double blend_ms = 0;    // a step: the two textures blended
  int flood_passes = 0;
  double total_ms() const {
    return seed_ms + flood_ms + search_ms + convert_ms + decay_ms + blend_ms;
  }
};

// The source each voxel takes (-1: none), by the chosen algorithm. brute and splat are exact:
// they return the definition's winner. jfa* returns the source its flood settled on, which may
// not cover the voxel (its conversion then writes zero) or may not be the definition's winner.
std::vector<std::int32_t> vector_winners(const VectorVolume& volume,
                                         std::span<const VectorSource> sources,
                                         const VectorOptions& options,
                                         VectorPassTimes* times = nullptr);

// The conversion pass: each voxel's direction and strength from its winner, into `out` (which
// must have the volume's resolution).
void write_vector_texels(const VectorVolume& volume, std::span<const VectorSource> sources,
                         std::span<const std::int32_t> winners, VectorTexture& out);

// One generation: vector_winners then write_vector_texels. Throws InvalidArgument for an invalid
// volume or source, Cancelled when the interrupter says stop (nothing returned).
VectorTexture generate_vectors(const VectorVolume& volume, std::span<const VectorSource> sources,
                               VectorStorage storage, const VectorOptions& options = {},
                               VectorPassTimes* times = nullptr);

// How far an approximate generation is from the definition (docs/vectors.md).
struct VectorError {
  std::int64_t voxels = 0;
  std::int64_t source_differs = 0;  // voxels whose effective source (covering, else none) differs
  double max_angle_deg = 0;         // largest angle between directions, where both have one
  double max_strength_error = 0;    // largest |exact - approximate| strength
  double percent_differs() const { return voxels ? 100.0 * source_differs / voxels : 0; }
};
VectorError compare_vector_winners(const VectorVolume& volume,
                                   std::span<const VectorSource> sources,
                                   std::span<const std::int32_t> exact,
                                   std::span<const std::int32_t> approximate);

// The decay and blend of one step (docs/vectors.md), on decoded texels:
//   previous strength s_p <- max(0, s_p - decay_per_s * dt);
//   w = s_c / (s_c + s_p); direction = normalise(w n_c + (1 - w) n_p) (0 if that is 0); strength
//   = max(s_c, s_p). When both strengths are 0 the result is the zero texel; when one is 0 the
//   other texel's direction is kept as it is (w = 1 or 0, without renormalising). Float math.
VectorTexel blend_vector_texels(const VectorTexel& current, const VectorTexel& previous,
                                double decay_per_s, double dt_s);

// A field that moves with its sources: each step() generates the current texture from the
// sources and blends it with the decayed previous field into field(), the texture to sample.
class VectorSimulation {
 public:
  // Throws InvalidArgument for an invalid volume or a negative or non-finite decay.
  VectorSimulation(const VectorVolume& volume, VectorStorage storage, VectorOptions options,
                   double decay_per_s);
  ~VectorSimulation();
  VectorSimulation(VectorSimulation&&) noexcept;
  VectorSimulation& operator=(VectorSimulation&&) noexcept;

  // One step of dt seconds (> 0). Strong guarantee: if it throws, field() is unchanged. The
  // conversion, decay and blend run fused in one sweep over the texels (last_times().blend_ms);
  // with splatting the search costs what the sources cover (its scratch is kept between steps).
  void step(std::span<const VectorSource> sources, double dt_s);

  const VectorVolume& volume() const { return volume_; }
  const VectorTexture& current() const { return current_; }  // this step's generation
  const VectorTexture& field() const { return field_; }      // blended: what shaders sample
  const VectorPassTimes& last_times() const { return times_; }
  std::int64_t steps() const { return steps_; }

 private:
  VectorVolume volume_;
  VectorOptions options_;
  double decay_per_s_;
  VectorTexture current_, field_, next_;
  VectorPassTimes times_;
  std::int64_t steps_ = 0;
  struct Scratch;
  std::unique_ptr<Scratch> scratch_;
};

// A fixed time step that catches up: advance(frame_s) adds the frame's time and returns how many
// whole steps of dt to run now — at most max_steps_per_frame; time beyond what the cap lets
// through is dropped (dropped_s() counts it), so a stall never snowballs. Deterministic for a
// given sequence of frame times.
class FixedStepScheduler {
 public:
  // Throws InvalidArgument for dt <= 0 or non-finite, or max_steps_per_frame < 1.
  FixedStepScheduler(double dt_s, int max_steps_per_frame);
  int advance(double frame_s);  // throws InvalidArgument for a negative or non-finite frame time
  double dt_s() const { return dt_s_; }
  double pending_s() const { return accumulator_s_; }  // time not yet stepped (< dt after a call)
  double dropped_s() const { return dropped_s_; }

 private:
  double dt_s_;
  int max_steps_;
  double accumulator_s_ = 0;
  double dropped_s_ = 0;
};

// Trilinear sample of a texture at a world point, between voxel centres (clamped to the outer
// centres inside the box). Outside the box: zero, inside = false.
struct VectorSample {
  Vec3d direction;  // the interpolated decoded direction (not renormalised)
  double strength = 0;
  bool inside = false;
  Vec3d vector() const { return direction * strength; }
};
VectorSample sample_vectors(const VectorVolume& volume, const VectorTexture& texture, Vec3d world);

// The debug visualiser: a camera at `eye` (world space) looking at the volume's centre (or at
// look_at), rays intersected with the box and marched front to back, density from strength and
// colour from direction (|component| per channel), over a dark background. With `sheet`, a
// reactive surface as well: a cloth across the box at sheet_height (a fraction of its z extent),
// each point displaced along the box's z axis by sheet_push world units per unit of the field's
// vector (direction x strength) at its rest position — what a game's grass or water surface does
// with the field — drawn opaque, lit, and tinted by the field's direction where it is strong.
struct VectorViewOptions {
  int width = 640, height = 480;
  Vec3d eye{0, 0, 0};  // (0,0,0) with auto_eye: placed from the box (an oblique view)
  bool auto_eye = true;
  std::optional<Vec3d> look_at;  // default: the box's centre
  double fov_deg = 45;
  double density = 8;  // opacity per world unit at strength 1, scaled by the box size
  bool sheet = false;
  double sheet_height = 0.3;  // 0..1 of the box's z extent
  double sheet_push = 0.6;    // world units per unit of field vector
};
Image render_vectors(const VectorVolume& volume, const VectorTexture& texture,
                     const VectorViewOptions& view = {});

}  // namespace voxfield
