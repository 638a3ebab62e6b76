// The vector-field model (docs/vectors.md): oriented volumes, voxel centres, sources and their
// index boxes, names, and the slab loop every pass runs on.
#include <chrono>
#include <cmath>
#include <string>

#include "vector_internal.h"
#include "voxfield/error.h"
#include "voxfield/interrupt.h"
#include "voxfield/parallel.h"
#include "voxfield/voxel_frame.h"

namespace voxfield {
namespace {

constexpr int kMaxResolution = 4096;

bool finite(Vec3d v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Vec3d column(const std::array<Vec3d, 3>& r, int c) {
  return {r[0][c], r[1][c], r[2][c]};
}

}  // namespace

std::array<Vec3d, 3> VectorVolume::rotation_about(double degrees, Vec3d axis) {
  return voxfield::rotation_about(degrees, axis);
}

std::int64_t VectorVolume::voxel_count() const {
  return Box3i::from_size(resolution).volume();
}

Vec3d VectorVolume::voxel_centre(int i, int j, int k) const {
  using detail::vectors::axis_offset;
  return centre + axis_offset(column(rotation, 2), size.z, k, resolution.z) +
         axis_offset(column(rotation, 1), size.y, j, resolution.y) +
         axis_offset(column(rotation, 0), size.x, i, resolution.x);
}

Vec3d VectorVolume::to_volume(Vec3d world) const {
  const Vec3d d = world - centre;
  // local = R^T d: the rows of R^T are R's columns.
  return {dot(column(rotation, 0), d) / size.x + 0.5, dot(column(rotation, 1), d) / size.y + 0.5,
          dot(column(rotation, 2), d) / size.z + 0.5};
}

Vec3d VectorVolume::to_world(Vec3d u) const {
  return centre + column(rotation, 0) * ((u.x - 0.5) * size.x) +
         column(rotation, 1) * ((u.y - 0.5) * size.y) +
         column(rotation, 2) * ((u.z - 0.5) * size.z);
}

Vec3d VectorVolume::voxel_size() const {
  return {size.x / resolution.x, size.y / resolution.y, size.z / resolution.z};
}

void VectorVolume::validate() const {
  if (!finite(centre)) throw InvalidArgument("vector volume: the centre must be finite");
  if (!finite(size) || size.x <= 0 || size.y <= 0 || size.z <= 0)
    throw InvalidArgument("vector volume: the size must be finite and positive on every axis");
  for (int a = 0; a < 3; ++a) {
    if (resolution[a] < 1 || resolution[a] > kMaxResolution)
      throw InvalidArgument("vector volume: the resolution must be 1.." +
                            std::to_string(kMaxResolution) + " on every axis (got " +
                            to_string(resolution) + ")");
  }
  for (int r = 0; r < 3; ++r) {
    if (!finite(rotation[r])) throw InvalidArgument("vector volume: the rotation must be finite");
    for (int c = 0; c < 3; ++c) {
      const double want = r == c ? 1.0 : 0.0;
      if (std::abs(dot(rotation[r], rotation[c]) - want) > 1e-6)
        throw InvalidArgument("vector volume: the rotation must be orthonormal");
    }
  }
  if (dot(cross(rotation[0], rotation[1]), rotation[2]) < 0)
    throw InvalidArgument("vector volume: the rotation must not mirror (determinant -1)");
}

void validate_sources(std::span<const VectorSource> sources) {
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const VectorSource& s = sources[i];
    if (!finite(s.position) || !finite(s.previous))
      throw InvalidArgument("source " + std::to_string(i) + ": positions must be finite");
    if (!std::isfinite(s.radius) || s.radius <= 0)
      throw InvalidArgument("source " + std::to_string(i) + ": the radius must be finite and > 0");
  }
}

const char* vector_rule_name(VectorRule r) {
  return r == VectorRule::kStrongest ? "strongest" : "nearest";
}
const char* vector_algorithm_name(VectorAlgorithm a) {
  switch (a) {
    case VectorAlgorithm::kBrute:
      return "brute";
    case VectorAlgorithm::kSplat:
      return "splat";
    case VectorAlgorithm::kJfa:
      return "jfa";
    case VectorAlgorithm::kJfaPlus1:
      return "jfa+1";
    case VectorAlgorithm::kJfaPlus2:
      return "jfa+2";
  }
  return "?";
}
const char* vector_storage_name(VectorStorage s) {
  switch (s) {
    case VectorStorage::kRgba8:
      return "rgba8";
    case VectorStorage::kRgba16f:
      return "rgba16f";
    case VectorStorage::kRgba32f:
      return "rgba32f";
  }
  return "?";
}
VectorRule parse_vector_rule(const std::string& name) {
  for (VectorRule r : {VectorRule::kStrongest, VectorRule::kNearest})
    if (name == vector_rule_name(r)) return r;
  throw InvalidArgument("unknown rule \"" + name + "\" (strongest or nearest)");
}
VectorAlgorithm parse_vector_algorithm(const std::string& name) {
  for (VectorAlgorithm a : {VectorAlgorithm::kBrute, VectorAlgorithm::kSplat, VectorAlgorithm::kJfa,
                            VectorAlgorithm::kJfaPlus1, VectorAlgorithm::kJfaPlus2})
    if (name == vector_algorithm_name(a)) return a;
  throw InvalidArgument("unknown vector algorithm \"" + name +
                        "\" (splat, brute, jfa, jfa+1, jfa+2)");
}
VectorStorage parse_vector_storage(const std::string& name) {
  for (VectorStorage s : {VectorStorage::kRgba8, VectorStorage::kRgba16f, VectorStorage::kRgba32f})
    if (name == vector_storage_name(s)) return s;
  throw InvalidArgument("unknown vector storage \"" + name + "\" (rgba8, rgba16f, rgba32f)");
}

namespace detail::vectors {

CentreTables::CentreTables(const VectorVolume& v) : centre(v.centre) {
  std::vector<Vec3d>* tables[3] = {&x, &y, &z};
  for (int a = 0; a < 3; ++a) {
    tables[a]->resize(static_cast<std::size_t>(v.resolution[a]));
    for (int n = 0; n < v.resolution[a]; ++n)
      (*tables[a])[n] = axis_offset(column(v.rotation, a), v.size[a], n, v.resolution[a]);
  }
}

IndexBox index_box(const VectorVolume& v, const VectorSource& s) {
  // The capsule in the box's own frame is still a capsule (rotations keep distances): its
  // bounding box there, in voxel-centre index coordinates t = u n - 1/2, bounds every voxel whose
  // centre it can reach.
  const Vec3d a = v.to_volume(s.previous), b = v.to_volume(s.position);
  IndexBox box;
  for (int axis = 0; axis < 3; ++axis) {
    const double n = v.resolution[axis], r = s.radius / v.size[axis];
    // Widened by half a voxel: a centre that rounding (large coordinates, a rotation orthonormal
    // only to 1e-6) puts just outside the bound is then tested, not skipped — the exact test
    // d < r decides, as in the oracle.
    const double lo = (std::min(a[axis], b[axis]) - r) * n - 0.5 - 0.5;
    const double hi = (std::max(a[axis], b[axis]) + r) * n - 0.5 + 0.5;
    if (!(hi >= 0) || !(lo <= n - 1)) return IndexBox{};
    box.lo[axis] = static_cast<int>(std::max(0.0, std::ceil(lo)));
    box.hi[axis] = static_cast<int>(std::min(n - 1, std::floor(hi)));
  }
  return box;
}

void for_each_slab(const VectorVolume& v, Interrupter* interrupter, std::string_view what,
                   const std::function<void(int, int)>& body) {
  const int nz = v.resolution.z;
  // Thin slabs (about 32 per thread, at least one z layer each): a step splats and sweeps a slab
  // while its rows are in the cache, and small slabs balance uneven work between the threads.
  const int slabs = std::min(nz, std::max(1, 32 * max_threads()));
  Progress progress(interrupter, what, slabs);
  parallel_for(static_cast<std::size_t>(slabs), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t s = b; s < e; ++s) {
      if (!progress.keep_going()) return;
      const int k0 = static_cast<int>(static_cast<std::int64_t>(nz) * s / slabs);
      const int k1 = static_cast<int>(static_cast<std::int64_t>(nz) * (s + 1) / slabs);
      body(k0, k1);
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
}

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
double ms_since(std::int64_t start_ns) {
  return (now_ns() - start_ns) / 1e6;
}

}  // namespace detail::vectors
}  // namespace voxfield
