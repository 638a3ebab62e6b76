// voxfield.mesh's engine: meshes of NumPy volumes (marching cubes, surface nets, dual contouring;
// docs/meshing.md) and the deformable terrain field with its brushes. The GIL is released while
// the C++ works; Ctrl-C stops a long mesh (voxfield.Cancelled).
//
// Arrays: a volume a[i, j, k] has i along x, as scikit-image and voxfield's .npy files index
// them, so vertex (x, y, z) = (i, j, k) * spacing; it is read in place when it is float32 in
// Fortran order (x fastest), converted once otherwise.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>

#include "mesh_arrays.h"
#include "signals.h"
#include "voxfield/error.h"
#include "voxfield/mesh.h"
#include "voxfield/parallel.h"
#include "voxfield/terrain.h"

namespace py = pybind11;

namespace voxfield::python {

void bind_mesh_input(py::module_& m);  // mesh_input.cpp

namespace {

using Volume = py::array_t<float, py::array::f_style | py::array::forcecast>;

MeshOptions mesh_options(const std::string& algorithm, int chunk) {
  MeshOptions o;
  o.algorithm = parse_mesher(algorithm);
  o.chunk_edge = chunk;
  return o;
}

Vec3d vec(const std::vector<double>& v, const char* what) {
  if (v.size() != 3) throw InvalidArgument(std::string(what) + " takes three numbers (x, y, z)");
  return {v[0], v[1], v[2]};
}

// A terrain shared by Python threads: its methods release the GIL while voxfield works, so a
// brush (a writer) takes the lock alone and readers (values, materials, meshes) share it — each
// after the GIL is released, so a thread waiting for the lock never holds the GIL.
struct PyTerrain {
  TerrainField field;
  mutable std::shared_mutex lock;
  explicit PyTerrain(const TerrainOptions& o) : field(o) {}
};

std::string repr(const TerrainField& t) {
  const TerrainOptions& o = t.options();
  const TerrainField::Memory m = t.memory();
  return "voxfield.mesh.Terrain(samples=(" + std::to_string(o.samples.x) + ", " +
         std::to_string(o.samples.y) + ", " + std::to_string(o.samples.z) + "), storage='" +
         terrain_storage_name(o.storage) +
         "', max_distance=" + std::to_string(t.max_distance_units()) +
         ", bytes=" + std::to_string(m.bytes) + ")";
}

}  // namespace

void bind_mesh(py::module_& parent) {
  py::module_ m = parent.def_submodule("mesh", "Meshes of volumes and terrain (docs/meshing.md)");
  m.def(
      "mesh_volume",
      [](const Volume& volume, double level, std::vector<double> spacing, const std::string& inside,
         const std::string& algorithm, int chunk, int threads) {
        if (volume.ndim() != 3) throw InvalidArgument("volume must be a 3-D array");
        if (inside != "below" && inside != "above")
          throw InvalidArgument("inside must be 'below' or 'above', not '" + inside + "'");
        ScalarVolume v;
        v.size = {static_cast<int>(volume.shape(0)), static_cast<int>(volume.shape(1)),
                  static_cast<int>(volume.shape(2))};
        v.values = volume.data();
        const Vec3d s = vec(spacing, "spacing");
        v.spacing_units = {s.x, s.y, s.z};
        MeshOptions o = mesh_options(algorithm, chunk);
        o.iso = level;
        o.inside_above = inside == "above";
        PythonSignals signals;
        o.interrupter = &signals;
        const Mesh mesh = without_gil(threads, [&] { return mesh_volume(v, o); });
        return to_arrays(mesh, false);
      },
      py::arg("volume"), py::arg("level") = 0.0, py::arg("spacing") = std::vector<double>{1, 1, 1},
      py::arg("inside") = "below", py::arg("algorithm") = "mc", py::arg("chunk") = 32,
      py::arg("threads") = 0,
      "The iso-surface of a 3-D volume at `level` as (vertices float32 (V, 3), faces uint32 (F, 3) "
      "counter-clockwise seen from outside, normals float32 (V, 3), unit, pointing out). "
      "Vertex (x, y, z) = (i, j, k) * spacing for a[i, j, k]; inside='below' (a signed distance "
      "field) or 'above' (a density); algorithm 'mc', 'sn' or 'dc'; chunk: cells per chunk edge "
      "(2..256); threads: at most this many (0: every core). The GIL is released meanwhile.");

  py::class_<PyTerrain>(m, "Terrain",
                           "A deformable terrain field: a signed lattice in i8, i16 or f32 chunks, "
                           "edited by brushes (docs/meshing.md, 'Terrain fields')")
      .def(py::init([](std::vector<int> samples, const std::string& storage, double spacing,
                       std::vector<double> origin, double max_distance, int chunk,
                       bool positive_inside,
                       std::optional<py::array_t<std::uint8_t, py::array::c_style |
                                                                py::array::forcecast>> palette) {
             if (samples.size() != 3) throw InvalidArgument("samples takes three integers");
             TerrainOptions o;
             o.samples = {samples[0], samples[1], samples[2]};
             o.storage = parse_terrain_storage(storage);
             o.spacing_units = spacing;
             const Vec3d at = vec(origin, "origin");
             o.origin_units = {at.x, at.y, at.z};
             o.max_distance_units = max_distance;
             o.chunk_edge = chunk;
             o.positive_inside = positive_inside;
             if (palette) {
               if (palette->ndim() != 2 || palette->shape(0) != 256 || palette->shape(1) != 3)
                 throw InvalidArgument("palette must be a uint8 array of shape (256, 3)");
               Palette p{};
               for (std::size_t i = 0; i < 256; ++i)
                 p[i] = {palette->at(i, 0), palette->at(i, 1), palette->at(i, 2), 255};
               o.palette = p;
             }
             return std::make_unique<PyTerrain>(o);
           }),
           py::arg("samples"), py::arg("storage") = "i16", py::arg("spacing") = 1.0,
           py::arg("origin") = std::vector<double>{0, 0, 0}, py::arg("max_distance") = 0.0,
           py::arg("chunk") = 16, py::arg("positive_inside") = false,
           py::arg("palette") = py::none(),
           "samples: (nx, ny, nz); storage 'i8', 'i16' or 'f32'; max_distance (the clamp) in "
           "world units (0: the storage's default); palette: uint8 (256, 3) colours by material "
           "for meshes")
      .def("__repr__",
           [](const PyTerrain& t) {
             py::gil_scoped_release release;
             std::shared_lock read(t.lock);
             return repr(t.field);
           })
      .def_property_readonly("samples",
                             [](const PyTerrain& t) {  // fixed at construction: no lock
                               const Vec3i n = t.field.size();
                               return py::make_tuple(n.x, n.y, n.z);
                             })
      .def_property_readonly(
          "max_distance", [](const PyTerrain& t) { return t.field.max_distance_units(); },
          "stored values lie within ±max_distance (the clamp, world units)")
      .def_property_readonly(
          "step", [](const PyTerrain& t) { return t.field.step_units(); },
          "the quantisation step (0 for f32)")
      .def_property_readonly("memory",
                             [](const PyTerrain& t) {
                               TerrainField::Memory mem;
                               {
                                 py::gil_scoped_release release;
                                 std::shared_lock read(t.lock);
                                 mem = t.field.memory();
                               }
                               py::dict d;
                               d["chunks"] = mem.chunks, d["uniform_chunks"] = mem.uniform_chunks;
                               d["bytes"] = mem.bytes;
                               return d;
                             })
      .def(
          "assign",
          [](PyTerrain& t, const Volume& values, std::uint8_t material) {
            if (values.ndim() != 3) throw InvalidArgument("values must be a 3-D array");
            ScalarVolume v;
            v.size = {static_cast<int>(values.shape(0)), static_cast<int>(values.shape(1)),
                      static_cast<int>(values.shape(2))};
            v.values = values.data();
            py::gil_scoped_release release;
            std::unique_lock write(t.lock);
            t.field.assign(v, material);
          },
          py::arg("values"), py::arg("material") = 0,
          "Every sample from an array a[i, j, k] of the terrain's shape (signed distances in world "
          "units, in the terrain's sign convention), and one material for all")
      .def(
          "apply",
          [](PyTerrain& t, const std::string& shape, const std::string& mode,
             std::vector<double> centre, double radius, std::optional<std::vector<double>> end,
             std::optional<std::vector<double>> half_extents, double smooth, std::uint8_t material) {
            TerrainBrush b;
            if (shape == "sphere") b.shape = TerrainBrush::Shape::kSphere;
            else if (shape == "box") b.shape = TerrainBrush::Shape::kBox;
            else if (shape == "capsule") b.shape = TerrainBrush::Shape::kCapsule;
            else throw InvalidArgument("shape must be 'sphere', 'box' or 'capsule', not '" + shape + "'");
            if (mode == "add") b.mode = TerrainBrush::Mode::kAdd;
            else if (mode == "subtract") b.mode = TerrainBrush::Mode::kSubtract;
            else throw InvalidArgument("mode must be 'add' or 'subtract', not '" + mode + "'");
            b.centre_units = vec(centre, "centre");
            b.radius_units = radius;
            if (b.shape == TerrainBrush::Shape::kCapsule) {
              if (!end) throw InvalidArgument("a capsule needs its second end: end=(x, y, z)");
              b.end_units = vec(*end, "end");
            }
            if (b.shape == TerrainBrush::Shape::kBox) {
              if (!half_extents)
                throw InvalidArgument("a box needs its half extents: half_extents=(hx, hy, hz)");
              b.half_extents_units = vec(*half_extents, "half_extents");
            }
            b.smooth_units = smooth;
            b.material = material;
            Box3i changed;
            {
              py::gil_scoped_release release;
              std::unique_lock write(t.lock);
              changed = t.field.apply(b);
            }
            if (changed.empty()) return py::object(py::none());
            return py::object(py::make_tuple(
                py::make_tuple(changed.begin.x, changed.begin.y, changed.begin.z),
                py::make_tuple(changed.end.x, changed.end.y, changed.end.z)));
          },
          py::arg("shape"), py::arg("mode") = "add", py::kw_only(), py::arg("centre"), py::arg("radius") = 1.0,
          py::arg("end") = py::none(), py::arg("half_extents") = py::none(),
          py::arg("smooth") = 0.0, py::arg("material") = 1,
          "Adds or subtracts a sphere, box or capsule (world units), sharp or blended over "
          "`smooth`; returns the changed samples as ((x0, y0, z0), (x1, y1, z1)), end exclusive, "
          "or None")
      .def(
          "values",
          [](const PyTerrain& t) {
            const Vec3i n = t.field.size();
            py::array_t<float, py::array::f_style> out({n.x, n.y, n.z});
            {
              float* data = out.mutable_data();
              py::gil_scoped_release release;
              std::shared_lock read(t.lock);
              t.field.decode(Box3i::from_size(n), data);
            }
            return out;
          },
          "The decoded samples as float32 a[i, j, k] (Fortran order), in the terrain's sign "
          "convention")
      .def(
          "materials",
          [](const PyTerrain& t) {
            const Vec3i n = t.field.size();
            py::array_t<std::uint8_t, py::array::f_style> out({n.x, n.y, n.z});
            std::uint8_t* p = out.mutable_data();
            {
              py::gil_scoped_release release;
              std::shared_lock read(t.lock);
              t.field.read_codes(Box3i::from_size(n), nullptr, p);  // x fastest: Fortran order
            }
            return out;
          },
          "The material of every sample, uint8 a[i, j, k]")
      .def(
          "mesh",
          [](const PyTerrain& t, const std::string& algorithm, int chunk) {
            MeshOptions o = mesh_options(algorithm, chunk);
            PythonSignals signals;
            o.interrupter = &signals;
            Mesh mesh;
            {
              py::gil_scoped_release release;
              std::shared_lock read(t.lock);
              mesh = mesh_terrain(t.field, o);
            }
            return to_arrays(mesh, true);
          },
          py::arg("algorithm") = "mc", py::arg("chunk") = 32,
          "The surface as (vertices, faces, normals, colors uint8 (V, 3)); colours by material "
          "from the palette (zeros without one)");
  bind_mesh_input(m);
}

}  // namespace voxfield::python
