// What voxfield.world's bindings share (internal to the extension): the Python World, boxes as
// pairs of triples, and distance fields as NumPy arrays.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/mesh.h"
#include "voxfield/world.h"

namespace voxfield::python {

// A world, the volume its file declared (arrays and fields cover it by default), and a lock:
// methods release the GIL while voxfield works, so readers (arrays, fields, frames, meshes, saves)
// share the lock and writers (edits, fills, the palette) take it alone — each after releasing the
// GIL, so a thread waiting for the lock never holds the GIL.
struct PyWorld {
  World world;
  Box3i extent;
  mutable std::shared_mutex lock;
  PyWorld(World w, Box3i e) : world(std::move(w)), extent(e) {}
};

using Triple = std::array<int, 3>;
using OptionalBox = std::optional<std::pair<Triple, Triple>>;
inline Vec3i vec3(const Triple& t) {
  return {t[0], t[1], t[2]};
}
inline pybind11::tuple triple(Vec3i v) {
  return pybind11::make_tuple(v.x, v.y, v.z);
}
inline pybind11::object box_tuple(const Box3i& b) {
  if (b.empty()) return pybind11::none();
  return pybind11::make_tuple(triple(b.begin), triple(b.end));
}

// f() with the GIL released and the world's lock shared: every read of a world goes through it
// (or takes the lock itself), since edits on other threads change its chunks meanwhile.
template <class F>
auto reading(const PyWorld& w, F&& f) {
  const pybind11::gil_scoped_release release;
  const std::shared_lock read(w.lock);
  return f();
}

// The box [begin, end) given as two triples, or the world's extent united with its content.
inline Box3i box_of(const PyWorld& w, const OptionalBox& box) {
  if (box) return Box3i{vec3(box->first), vec3(box->second)};
  return w.extent.unite(w.world.voxels.content_bounds());
}

// A world mesher's options from Python's keywords (voxfield.world.mesh and LiveMesh).
inline MeshOptions world_mesh_options(const std::string& algorithm, double iso, int chunk) {
  MeshOptions o;
  o.algorithm = parse_mesher(algorithm);
  o.iso = iso;
  o.chunk_edge = chunk;
  return o;
}

// The options of a field; its domain is set by with_domain, under the world's lock.
inline DistanceOptions field_options(const std::string& metric, bool is_signed, double max_distance,
                                     const std::string& storage, std::array<double, 3> spacing,
                                     bool sites) {
  DistanceOptions o;
  o.metric = parse_metric(metric);
  o.signed_distance = is_signed;
  o.max_distance = max_distance;
  o.storage = parse_storage(storage);
  o.spacing = spacing;
  o.nearest_sites = sites;
  return o;
}

// `o` over `box` (default: the world's extent), checked non-empty; `who` names the caller in the
// error. Call with the world's lock held.
inline DistanceOptions with_domain(DistanceOptions o, const PyWorld& w, const OptionalBox& box,
                                   const std::string& who) {
  o.domain = box_of(w, box);
  if (o.domain->empty()) throw InvalidArgument(who + ": the world holds no volume");
  return o;
}

// A field's stored values and sites copied out densely (x fastest), done without the GIL.
struct DenseField {
  Vec3i size;
  std::size_t width = 4;  // bytes per stored value
  std::vector<std::uint8_t> values;
  std::vector<std::int16_t> sites;  // 3 per voxel, when asked for
  DistanceEncoding encoding;
  Vec3i origin;  // the domain's first voxel
  bool with_sites = false;
};
DenseField dense_field(const DistanceField& f, bool sites);
// (distances a[x, y, z] as stored, {"scale", "bias", "origin"}[, sites int16 (X, Y, Z, 3)]).
pybind11::tuple to_python(const DenseField& f);

}  // namespace voxfield::python
