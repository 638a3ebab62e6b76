// voxfield — editing worlds: brushes, operations, and the record of what changed.
//
// An Edit applies one operation with one brush:
//   place  sets the voxels inside the brush to a material (stamp: to the model's materials);
//   carve  sets them to air;
//   paint  recolours the solid voxels inside the brush, leaving air as it is.
// Brushes reaching outside a bounded world are clipped to it; nothing outside is touched.
// DirtyRegions records, per chunk, the exact box of voxels that changed, which is what an
// incremental distance update needs.
#pragma once

#include <array>
#include <memory>
#include <unordered_map>
#include <variant>
#include <vector>

#include "voxfield/world.h"

namespace voxfield {

// Voxels p with |p - center|^2 <= radius^2 (voxel centres at integer coordinates).
struct SphereBrush {
  Vec3d center{0, 0, 0};
  double radius = 1;
};
// Voxels with min <= p <= max on every axis (inclusive).
struct BoxBrush {
  Vec3i min, max;
};
// An oriented box: voxels whose offset from `center`, expressed in the box's axes, lies within
// +-half_extent. The axes are the world axes rotated by `rotation_deg` = (about x, about y, about
// z), applied in that order (x first).
struct RotatedBoxBrush {
  Vec3d center{0, 0, 0};
  Vec3d half_extent{1, 1, 1};
  Vec3d rotation_deg{0, 0, 0};
};
// A stroke: voxels within `radius` of the segment a-b.
struct CapsuleBrush {
  Vec3d a{0, 0, 0}, b{0, 0, 0};
  double radius = 1;
};
// Another world pasted with its voxel v at v + offset; the model's air voxels are not part of it.
struct StampBrush {
  std::shared_ptr<const World> model;
  Vec3i offset;
};

using Brush = std::variant<SphereBrush, BoxBrush, RotatedBoxBrush, CapsuleBrush, StampBrush>;

enum class EditOp { kPlace, kCarve, kPaint };

struct Edit {
  EditOp op = EditOp::kPlace;
  Brush brush;
  std::uint8_t material = 1;  // place / paint (stamps use their own materials); must be non-zero
};

// Boxes of changed voxels, kept per chunk (the union of the changes inside that chunk).
class DirtyRegions {
 public:
  enum class Track {
    kAnyChange,  // every material change (renderers, meshers)
    kOccupancy,  // only solid <-> air changes: all a distance field depends on
  };
  explicit DirtyRegions(int chunk_edge = Grid<std::uint8_t>::kDefaultChunkEdge,
                        Track track = Track::kAnyChange);
  Track track() const { return track_; }
  // Records a change. `removes_solid` / `adds_solid`: whether it may have turned solid voxels into
  // air / air into solid (a distance field updates changes of one kind only more cheaply).
  void add(const Box3i& changed, bool removes_solid = true, bool adds_solid = true);
  bool empty() const { return per_chunk_.empty(); }
  void clear() {
    per_chunk_.clear();
    removes_solid_ = false;
    adds_solid_ = false;
  }
  // Whether any recorded change may have removed / added a solid voxel.
  bool removes_solid() const { return removes_solid_; }
  bool adds_solid() const { return adds_solid_; }
  // Per-chunk boxes, sorted by chunk (z, y, x).
  std::vector<Box3i> boxes() const;
  // The union of everything recorded (empty box if nothing).
  Box3i bounds() const;

 private:
  struct Hash {
    std::size_t operator()(const Vec3i& c) const noexcept {
      return static_cast<std::size_t>(c.x) * 73856093u ^ static_cast<std::size_t>(c.y) * 19349663u ^
             static_cast<std::size_t>(c.z) * 83492791u;
    }
  };
  int shift_;
  Track track_;
  bool removes_solid_ = false;
  bool adds_solid_ = false;
  std::unordered_map<Vec3i, Box3i, Hash> per_chunk_;
};

// The voxels a brush may touch (before clipping to a world).
Box3i brush_bounds(const Brush& brush);
// Whether voxel p is inside the brush (for stamps: the model voxel at p - offset is solid). The
// per-shape overloads skip the variant dispatch in loops over many voxels.
bool brush_contains(const Brush& brush, Vec3i p);
bool brush_contains(const SphereBrush& brush, Vec3i p);
bool brush_contains(const BoxBrush& brush, Vec3i p);
bool brush_contains(const RotatedBoxBrush& brush, Vec3i p);
bool brush_contains(const CapsuleBrush& brush, Vec3i p);
bool brush_contains(const StampBrush& brush, Vec3i p);

struct EditResult {
  Box3i changed_box;  // smallest box holding every changed voxel (empty if none)
  std::int64_t voxels_changed = 0;
};

// Throws InvalidArgument for a malformed edit (see apply_edit); does nothing otherwise.
void validate_edit(const Edit& edit);

// Applies an edit; records the changed voxels in `dirty` when given. Throws InvalidArgument for a
// malformed edit (radius < 0, min > max, material 0 with place or paint, a stamp without a model)
// before changing anything.
EditResult apply_edit(World& world, const Edit& edit, DirtyRegions* dirty = nullptr);

}  // namespace voxfield
