// voxfield — exact distance fields from voxel grids.
//
// A distance field assigns every voxel of a domain the distance between its centre and the centre
// of the nearest "site" voxel:
//  * unsigned: sites are the solid voxels (material != 0); a solid voxel reads 0;
//  * signed: air voxels read their distance to the nearest solid voxel, solid voxels read
//    -(distance to the nearest air voxel), so the surface lies between -1 and +1.
// Metrics: Manhattan (L1), Chebyshev (L-infinity) and Euclidean (L2, optionally with anisotropic
// voxel spacing). The computation is exact: see docs/distance.md for the algorithm (separable
// passes after Meijster, Roerdink & Hesselink 2000) and for the tie-breaking rule of nearest sites.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <variant>

#include "voxfield/grid.h"
#include "voxfield/voxel_frame.h"
#include "voxfield/world.h"

namespace voxfield {

class Interrupter;

enum class Metric { kManhattan, kChebyshev, kEuclidean };
enum class Storage { kU8, kU16, kF32 };

const char* metric_name(Metric m);    // "manhattan", "chebyshev", "euclidean"
const char* storage_name(Storage s);  // "u8", "u16", "f32"
// Parse the names above; throw InvalidArgument for anything else.
Metric parse_metric(const std::string& name);
Storage parse_storage(const std::string& name);

struct DistanceOptions {
  Metric metric = Metric::kManhattan;
  bool signed_distance = false;
  // Clamp D in distance units (voxels, or spacing units for anisotropic Euclidean fields):
  // values beyond D read D (and -D inside). 0 = no clamp.
  double max_distance = 0;
  Storage storage = Storage::kF32;
  // Size of a voxel along x, y, z (e.g. metres). Euclidean only; must be positive.
  std::array<double, 3> spacing{1, 1, 1};
  // Integer storage of Euclidean distances keeps floor(d * scale): rounded down, so a stored value
  // never exceeds the true distance (safe for sphere tracing). 0 picks the default: 4 for u8
  // (quarter voxels up to 63.75), 16 for u16 (1/16 voxel up to 4095.9). Manhattan and Chebyshev
  // distances are integers and are stored with scale 1.
  double fixed_point_scale = 0;
  // Also compute, for every voxel, the offset to its nearest site (the feature transform).
  bool nearest_sites = false;
  // Voxels to compute. Default: the world's bounds if it has any, else its content box grown by
  // D (by one voxel when unclamped, so that the air around the content is included). Voxels
  // outside the domain read the field's background (D when clamped, +inf or the type's maximum
  // otherwise). Sites outside the domain are ignored.
  std::optional<Box3i> domain;
  // Progress and cancellation of the exact transform (interrupt.h): told how far its passes are,
  // asked between columns and slices; cancelling throws Cancelled and returns nothing. Never kept:
  // a returned field's options and a DynamicDistanceField (after its first build) hold null.
  Interrupter* interrupter = nullptr;
};

// Offset from a voxel to its nearest site, in voxels. `none()` when no site lies within the clamp
// (or anywhere, for an empty world).
struct SiteOffset {
  static constexpr std::int16_t kNone = std::numeric_limits<std::int16_t>::min();
  std::int16_t dx = kNone, dy = kNone, dz = kNone;
  bool none() const { return dx == kNone; }
  friend constexpr bool operator==(const SiteOffset&, const SiteOffset&) = default;
};

// How stored values map to distances. Integer storage: stored = bias + floor(d * scale), clamped
// to the type's range; bias is 0 for unsigned fields and 2^(bits-1) (128 or 32768) for signed
// ones. f32 storage holds d itself (scale 1, bias 0).
struct DistanceEncoding {
  double scale = 1;
  std::int64_t bias = 0;
  double decode(double stored) const { return (stored - static_cast<double>(bias)) / scale; }
};

struct DistanceField {
  DistanceOptions options;
  Box3i domain;
  DistanceEncoding encoding;
  // One of three grids, matching options.storage; same chunk edge and bounds as the world.
  std::variant<Grid<std::uint8_t>, Grid<std::uint16_t>, Grid<float>> values;
  // Offsets to the nearest site, when options.nearest_sites.
  std::optional<Grid<SiteOffset>> sites;
  // Where its voxels sit in the world: its world's frame (voxel_frame.h). It places the field; the
  // values stay in voxel edges times options.spacing.
  VoxelFrame frame;

  // The distance at p (decoded; +inf where nothing is within reach of an unclamped f32 field).
  double distance(Vec3i p) const;
  int chunk_edge() const;
};

// FNV-1a (64-bit) of the domain, the encoding, the stored values over the domain (x fastest) and
// the nearest sites when present: the same field hashes the same on every machine whatever its
// chunk edge, so benchmarks print it beside their times and results can be pinned.
std::uint64_t content_hash(const DistanceField& field);

// Computes the exact field of `world` (solid = material != 0). Throws InvalidArgument for options
// out of range (negative clamp, spacing <= 0, spacing with a non-Euclidean metric, a domain whose
// nearest-site offsets would not fit 16 bits, a spacing too fine for integer storage).
// Multi-threaded on voxfield's pool; the result does not depend on the thread count or chunk edge.
DistanceField compute_distance_field(const World& world, const DistanceOptions& options);
// The same for any occupancy grid (non-zero = solid).
DistanceField compute_distance_field(const Grid<std::uint8_t>& occupancy,
                                     const DistanceOptions& options);

// A caller's dense array of distances over a field's domain: the voxel at domain.begin + (x, y, z)
// is data[x * stride[0] + y * stride[1] + z * stride[2]] (strides in elements, any order: x
// fastest is {1, nx, nx * ny}; NumPy's C order of a (z, y, x) array is the same). The caller
// keeps the array alive and large enough for the domain, and no two voxels may share an element.
template <class T>
struct DenseDistances {
  T* data = nullptr;
  std::array<std::ptrdiff_t, 3> stride{0, 0, 0};
};

// The exact field of `occupancy` written straight into `out` instead of a DistanceField: the
// distance in distance units (a square root taken in double from the exact squared distance);
// where no site lies within the clamp D, D (+inf unclamped); solid voxels of signed fields read
// minus their distance to air (-D, -inf beyond). For callers that want a dense array anyway
// (voxfield.ndimage, image pipelines): no field grid is built, encoded and copied. The array
// covers `options.domain`, which must be given unless the grid has bounds (then it defaults to
// them). Refused (InvalidArgument, nothing written): `options.nearest_sites`, a null array, a
// zero stride along an axis longer than one voxel, and the options compute_distance_field refuses
// for f32 storage (`options.storage` does not apply). Cancelling through the interrupter throws
// Cancelled and leaves `out` partly written.
void compute_distance_field_into(const Grid<std::uint8_t>& occupancy,
                                 const DistanceOptions& options, const DenseDistances<double>& out);
void compute_distance_field_into(const Grid<std::uint8_t>& occupancy,
                                 const DistanceOptions& options, const DenseDistances<float>& out);

}  // namespace voxfield
