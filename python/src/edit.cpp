// voxfield.world's editing: brushes applied to a World (place, carve, paint with a sphere, box,
// rotated box or capsule; docs/distance.md, "Editing"), the boxes they changed (dirty regions,
// per chunk), LiveField — an exact distance field kept equal to a rebuild through those edits by
// voxfield's incremental update, recomputing only what an edit can change — and LiveMesh, the
// world's surface kept per chunk through them (WorldMeshChunks).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "mesh_arrays.h"
#include "py_world.h"
#include "signals.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/edit.h"
#include "voxfield/error.h"
#include "voxfield/mesh_chunks.h"

namespace py = pybind11;

namespace voxfield::python {
namespace {

using OptionalVec = std::optional<std::array<double, 3>>;
using OptionalInts = std::optional<Triple>;

Vec3d vec3d(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

// One edit from Python's keywords; names the missing or stray argument.
Edit make_edit(const std::string& op, const std::string& shape, const OptionalVec& center,
               double radius, const OptionalInts& min, const OptionalInts& max,
               const OptionalVec& a, const OptionalVec& b, const OptionalVec& half_extent,
               const OptionalVec& rotation_deg, int material) {
  Edit e;
  if (op == "place")
    e.op = EditOp::kPlace;
  else if (op == "carve")
    e.op = EditOp::kCarve;
  else if (op == "paint")
    e.op = EditOp::kPaint;
  else
    throw InvalidArgument("op must be 'place', 'carve' or 'paint', not '" + op + "'");
  if (material < 1 || material > 255)
    throw InvalidArgument("material must be 1..255, not " + std::to_string(material));
  e.material = static_cast<std::uint8_t>(material);
  const auto need = [&](bool given, const char* what) {
    if (!given) throw InvalidArgument("a " + shape + " brush needs " + what);
  };
  if (shape == "sphere") {
    need(center.has_value(), "center");
    e.brush = SphereBrush{vec3d(*center), radius};
  } else if (shape == "box") {
    need(min && max, "min and max (inclusive voxel corners)");
    e.brush = BoxBrush{vec3(*min), vec3(*max)};
  } else if (shape == "rotated_box") {
    need(center && half_extent, "center and half_extent");
    e.brush = RotatedBoxBrush{vec3d(*center), vec3d(*half_extent),
                              rotation_deg ? vec3d(*rotation_deg) : Vec3d{0, 0, 0}};
  } else if (shape == "capsule") {
    need(a && b, "a and b (the segment's ends)");
    e.brush = CapsuleBrush{vec3d(*a), vec3d(*b), radius};
  } else {
    throw InvalidArgument("shape must be 'sphere', 'box', 'rotated_box' or 'capsule', not '" +
                          shape + "'");
  }
  validate_edit(e);
  return e;
}

// (changed box or None, voxels changed, the dirty regions' per-chunk boxes).
py::tuple result(const EditResult& r, const DirtyRegions& dirty) {
  py::list boxes;
  for (const Box3i& b : dirty.boxes()) boxes.append(box_tuple(b));
  return py::make_tuple(box_tuple(r.changed_box), r.voxels_changed, boxes);
}

// The field and its world: the world object is kept alive by the Python binding (keep_alive).
struct PyLiveField {
  PyWorld& world;
  std::optional<DynamicDistanceField> field;
  bool sites = false;
};

// A world's surface kept per chunk through the edits made with its apply().
struct PyLiveMesh {
  PyWorld& world;
  std::optional<WorldMeshChunks> mesh;  // none after an update and the meshing after it failed
};

template <class LiveMesh>
auto& kept_mesh(LiveMesh& f) {
  if (!f.mesh)
    throw InvalidArgument(
        "LiveMesh: the mesh was lost when an update and meshing the world again both failed; "
        "make a new LiveMesh");
  return *f.mesh;
}

#define VOXFIELD_EDIT_ARGS                                                                  \
  py::arg("op"), py::arg("shape"), py::kw_only(),                                           \
      py::arg("center") = py::none(), py::arg("radius") = 1.0, py::arg("min") = py::none(), \
      py::arg("max") = py::none(), py::arg("a") = py::none(), py::arg("b") = py::none(),    \
      py::arg("half_extent") = py::none(), py::arg("rotation_deg") = py::none(),            \
      py::arg("material") = 1

}  // namespace

void bind_edit(py::module_& m, py::class_<PyWorld>& world) {
  world.def(
      "apply",
      [](PyWorld& w, const std::string& op, const std::string& shape, OptionalVec center,
         double radius, OptionalInts min, OptionalInts max, OptionalVec a, OptionalVec b,
         OptionalVec half_extent, OptionalVec rotation_deg, int material) {
        const Edit e = make_edit(op, shape, center, radius, min, max, a, b, half_extent,
                                 rotation_deg, material);
        DirtyRegions dirty(w.world.voxels.chunk_edge());
        EditResult r;
        {
          py::gil_scoped_release release;
          const std::unique_lock write(w.lock);
          r = apply_edit(w.world, e, &dirty);
        }
        return result(r, dirty);
      },
      VOXFIELD_EDIT_ARGS,
      "Applies one edit; returns (changed box or None, voxels changed, per-chunk dirty boxes)");

  py::class_<PyLiveField>(m, "LiveField",
                          "An exact distance field of a World kept equal to a rebuild through "
                          "edits applied with its apply()")
      .def(py::init([](PyWorld& w, const std::string& metric, bool is_signed, double max_distance,
                       const std::string& storage, std::array<double, 3> spacing, bool sites,
                       OptionalBox box) {
             const DistanceOptions o =
                 field_options(metric, is_signed, max_distance, storage, spacing, sites);
             auto f = std::make_unique<PyLiveField>(PyLiveField{w, std::nullopt, sites});
             py::gil_scoped_release release;
             const std::shared_lock read(w.lock);
             // The domain is fixed: edits never grow it.
             f->field.emplace(w.world, with_domain(o, w, box, "LiveField"));
             return f;
           }),
           py::keep_alive<1, 2>(), py::arg("world"), py::arg("metric") = "euclidean",
           py::arg("signed") = false, py::arg("max_distance") = 0.0, py::arg("storage") = "f32",
           py::arg("spacing") = std::array<double, 3>{1, 1, 1}, py::arg("sites") = false,
           py::arg("box") = py::none(), "See voxfield.world.LiveField")
      .def(
          "apply",
          [](PyLiveField& f, const std::string& op, const std::string& shape, OptionalVec center,
             double radius, OptionalInts min, OptionalInts max, OptionalVec a, OptionalVec b,
             OptionalVec half_extent, OptionalVec rotation_deg, int material) {
            const Edit e = make_edit(op, shape, center, radius, min, max, a, b, half_extent,
                                     rotation_deg, material);
            PyWorld& w = f.world;
            DirtyRegions dirty(w.world.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy);
            EditResult r;
            DynamicDistanceField::UpdateStats st;
            {
              py::gil_scoped_release release;
              const std::unique_lock write(w.lock);
              r = apply_edit(w.world, e, &dirty);
              try {
                st = f.field->update(dirty);
              } catch (...) {
                // The world has the edit and a failed update leaves the field inexact
                // (dynamic_field.h): rebuilt, so the field never silently lags its world.
                f.field->rebuild();
                throw;
              }
            }
            py::tuple out = result(r, dirty);
            py::dict stats;
            stats["voxels_recomputed"] = st.voxels_recomputed;
            stats["voxels_read"] = st.voxels_read;
            stats["regions"] = st.regions;
            return py::make_tuple(out[0], out[1], out[2], stats);
          },
          VOXFIELD_EDIT_ARGS,
          "Applies one edit to the world and updates the field; returns (changed box or None, "
          "voxels changed, per-chunk boxes whose occupancy changed, update statistics)")
      .def(
          "rebuild",
          [](PyLiveField& f) {
            PythonSignals signals;
            py::gil_scoped_release release;
            const std::unique_lock write(f.world.lock);  // the field is written
            f.field->rebuild(&signals);
          },
          "Recomputes the whole field (after edits made to the world outside apply())")
      .def(
          "_field",
          [](const PyLiveField& f) {
            DenseField d;
            {
              py::gil_scoped_release release;
              const std::shared_lock read(f.world.lock);
              d = dense_field(f.field->field(), f.sites);
            }
            return to_python(d);
          },
          "(distances, encoding[, sites]): see LiveField.field()");

  py::class_<PyLiveMesh>(m, "LiveMesh",
                         "A World's surface kept per chunk, re-meshed where edits applied with "
                         "its apply() reach")
      .def(py::init([](PyWorld& w, const std::string& algorithm, double iso,
                       const std::string& metric, int chunk, OptionalBox box) {
             MeshOptions o = world_mesh_options(algorithm, iso, chunk);
             const Metric mt = parse_metric(metric);
             PythonSignals signals;
             o.interrupter = &signals;
             auto f = std::make_unique<PyLiveMesh>(PyLiveMesh{w, std::nullopt});
             py::gil_scoped_release release;
             const std::shared_lock read(w.lock);
             // The volume is fixed: by default the extent with the content, as arrays see it.
             const Box3i volume = box_of(w, box);
             if (volume.empty())
               throw InvalidArgument(box ? "LiveMesh: the box holds no voxels"
                                         : "LiveMesh: the world holds no volume");
             f->mesh.emplace(w.world, o, mt, volume);
             return f;
           }),
           py::keep_alive<1, 2>(), py::arg("world"), py::arg("algorithm") = "mc",
           py::arg("iso") = 0.0, py::arg("metric") = "euclidean", py::arg("chunk") = 32,
           py::arg("box") = py::none(), "See voxfield.world.LiveMesh")
      .def(
          "apply",
          [](PyLiveMesh& f, const std::string& op, const std::string& shape, OptionalVec center,
             double radius, OptionalInts min, OptionalInts max, OptionalVec a, OptionalVec b,
             OptionalVec half_extent, OptionalVec rotation_deg, int material) {
            const Edit e = make_edit(op, shape, center, radius, min, max, a, b, half_extent,
                                     rotation_deg, material);
            PyWorld& w = f.world;
            // Every change: a repaint re-colours the mesh.
            DirtyRegions dirty(w.world.voxels.chunk_edge(), DirtyRegions::Track::kAnyChange);
            EditResult r;
            std::vector<Vec3i> chunks;
            {
              py::gil_scoped_release release;
              const std::unique_lock write(w.lock);
              WorldMeshChunks& mesh = kept_mesh(f);
              r = apply_edit(w.world, e, &dirty);
              try {
                chunks = mesh.update(dirty);
              } catch (...) {
                // The mesh's field may be part new (WorldMeshChunks::update): meshed again, so
                // that the mesh never silently lags its world; if that fails too, none is kept.
                try {
                  mesh.rebuild();
                } catch (...) {
                  f.mesh.reset();
                }
                throw;
              }
            }
            py::tuple out = result(r, dirty);
            py::list remeshed;
            for (const Vec3i& c : chunks) remeshed.append(triple(c));
            return py::make_tuple(out[0], out[1], out[2], remeshed);
          },
          VOXFIELD_EDIT_ARGS,
          "Applies one edit to the world and re-meshes the chunks it reaches; returns (changed box "
          "or None, voxels changed, per-chunk dirty boxes, chunks re-meshed)")
      .def(
          "rebuild",
          [](PyLiveMesh& f) {
            py::gil_scoped_release release;
            const std::unique_lock write(f.world.lock);  // the mesh's field is written
            kept_mesh(f).rebuild();
          },
          "Meshes the world again (after edits made to it outside apply(), or a new palette)")
      .def(
          "mesh",
          [](const PyLiveMesh& f) {
            Mesh mesh;
            {
              py::gil_scoped_release release;
              const std::shared_lock read(f.world.lock);
              mesh = kept_mesh(f).merged();
            }
            return to_arrays(mesh, true);
          },
          "(vertices, faces, normals, colors) of the whole surface, as voxfield.world.mesh")
      .def(
          "chunk_mesh",
          [](const PyLiveMesh& f, Triple chunk) {
            Mesh mesh;
            {
              py::gil_scoped_release release;
              const std::shared_lock read(f.world.lock);
              mesh = kept_mesh(f).chunk_mesh(vec3(chunk));
            }
            return to_arrays(mesh, true);
          },
          py::arg("chunk"), "(vertices, faces, normals, colors) of one chunk's own mesh")
      .def_property_readonly(
          "chunk_count",
          [](const PyLiveMesh& f) {
            return triple(reading(f.world, [&] { return kept_mesh(f).chunk_count(); }));
          },
          "Chunks per axis");
}

}  // namespace voxfield::python
