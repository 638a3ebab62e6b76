// voxfield.mesh's meshes in (docs/mesh_input.md): triangle meshes read from OBJ, PLY, STL and OFF
// files or given as NumPy arrays, their generalized winding number (Jacobson et al. 2013, with
// Barill et al. 2018's hierarchy), solid voxels and signed distance fields. The GIL is released
// while the C++ works; Ctrl-C stops a voxelisation or a field (voxfield.Cancelled).
//
// Voxels are anchored at the origin, as in the C++ API: voxel (i, j, k) of the whole lattice spans
// [i, i + 1) x [j, j + 1) x [k, k + 1) times the voxel size and is sampled at its centre. Results
// cover mesh_voxel_box (the mesh's bounds grown by `padding` voxels) and come with that box's first
// voxel, so element a[i, j, k] is voxel first + (i, j, k), its centre at
// (first + (i, j, k) + 1/2) * voxel_size.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cstring>
#include <filesystem>
#include <optional>
#include <string>

#include "mesh_arrays.h"
#include "py_world.h"  // triple()
#include "signals.h"
#include "voxfield/error.h"
#include "voxfield/mesh_read.h"
#include "voxfield/mesh_voxelize.h"
#include "voxfield/parallel.h"

namespace py = pybind11;

namespace voxfield::python {
namespace {

using Points = py::array_t<double, py::array::c_style | py::array::forcecast>;
using Faces = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

// An (N, 3) array's rows, checked; `what` names it in the error.
void require_rows(const py::array& a, const char* what) {
  if (a.ndim() != 2 || a.shape(1) != 3)
    throw InvalidArgument(std::string(what) + " must be an (N, 3) array");
}

// The arrays as a TriangleMesh, validated (indices in range, positions finite).
TriangleMesh triangle_mesh(const Points& vertices, const Faces& faces) {
  require_rows(vertices, "vertices");
  require_rows(faces, "faces");
  TriangleMesh mesh;
  mesh.positions.resize(static_cast<std::size_t>(vertices.shape(0)));
  const double* v = vertices.data();
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    mesh.positions[i] = {v[3 * i], v[3 * i + 1], v[3 * i + 2]};
  mesh.triangles.resize(static_cast<std::size_t>(faces.shape(0)));
  const std::int64_t* f = faces.data();
  const auto count = static_cast<std::int64_t>(mesh.positions.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (std::size_t c = 0; c < 3; ++c) {
      const std::int64_t index = f[3 * t + c];
      if (index < 0 || index >= count)
        throw InvalidArgument("faces[" + std::to_string(t) + "] names vertex " +
                              std::to_string(index) + " of " + std::to_string(count));
      mesh.triangles[t][c] = static_cast<std::uint32_t>(index);
    }
  mesh.validate();
  return mesh;
}

py::tuple mesh_arrays(const TriangleMesh& mesh) {
  const auto nv = static_cast<py::ssize_t>(mesh.positions.size());
  const auto nf = static_cast<py::ssize_t>(mesh.triangles.size());
  py::array_t<double> vertices({nv, py::ssize_t{3}});
  py::array_t<std::uint32_t> faces({nf, py::ssize_t{3}});
  if (nv) std::memcpy(vertices.mutable_data(), mesh.positions.data(), mesh.positions.size() * 24);
  if (nf) std::memcpy(faces.mutable_data(), mesh.triangles.data(), mesh.triangles.size() * 12);
  return py::make_tuple(vertices, faces);
}

// Every point of an (N, 3) array through f, with the GIL released, in parallel.
template <class T, class F>
py::array_t<T> per_point(const Points& points, F&& f) {
  require_rows(points, "points");
  py::array_t<T> out(points.shape(0));
  const double* p = points.data();
  T* o = out.mutable_data();
  {
    py::gil_scoped_release release;
    parallel_for(static_cast<std::size_t>(points.shape(0)), 64,
                 [&](std::size_t begin, std::size_t end) {
                   for (std::size_t i = begin; i < end; ++i)
                     o[i] = f(std::array<double, 3>{p[3 * i], p[3 * i + 1], p[3 * i + 2]});
                 });
  }
  return out;
}

// The winding number with what its repr shows.
struct PyWinding {
  WindingNumber winding;
  std::size_t vertices, triangles;
  double accuracy;
};

MeshVoxelOptions voxel_options(double voxel_size, int padding, double accuracy) {
  MeshVoxelOptions o;
  o.voxel_size = voxel_size;
  o.padding_voxels = padding;
  o.accuracy = accuracy;
  return o;
}

}  // namespace

void bind_mesh_input(py::module_& m) {
  m.def(
      "read_mesh",
      [](const std::filesystem::path& path) {
        TriangleMesh mesh;
        {
          py::gil_scoped_release release;
          mesh = read_mesh(path);
        }
        return mesh_arrays(mesh);
      },
      py::arg("path"),
      "A triangle mesh from an OBJ, PLY (ASCII or binary), STL (ASCII or binary) or OFF file, by "
      "its extension, as (vertices float64 (V, 3) in the file's units, faces uint32 (F, 3)); "
      "polygons are fanned into triangles. Malformed files raise voxfield.FormatError naming the "
      "file and the byte offset");

  py::class_<PyWinding>(
      m, "WindingNumber",
      "The generalized winding number of a triangle mesh (Jacobson, Kavan & Sorkine-Hornung 2013): "
      "1 inside a closed surface, 0 outside, in between near a hole; evaluated with the hierarchy "
      "of Barill et al. 2018. Building sorts the triangles once; queries run on every core")
      .def(py::init([](const Points& vertices, const Faces& faces, double accuracy) {
             const TriangleMesh mesh = triangle_mesh(vertices, faces);
             py::gil_scoped_release release;
             return std::make_unique<PyWinding>(PyWinding{WindingNumber(mesh, accuracy),
                                                          mesh.positions.size(),
                                                          mesh.triangles.size(), accuracy});
           }),
           py::arg("vertices"), py::arg("faces"), py::arg("accuracy") = 2.0,
           "vertices (V, 3) in any units, faces (F, 3) counter-clockwise seen from outside; "
           "accuracy: Barill et al.'s beta (2, as in the paper; larger is more exact and slower)")
      .def(
          "__call__",
          [](const PyWinding& w, const Points& points) {
            return per_point<double>(points,
                                     [&](const std::array<double, 3>& p) { return w.winding(p); });
          },
          py::arg("points"), "The hierarchical winding number at each point: float64 (N,)")
      .def(
          "exact",
          [](const PyWinding& w, const Points& points) {
            return per_point<double>(
                points, [&](const std::array<double, 3>& p) { return w.winding.exact(p); });
          },
          py::arg("points"),
          "The exact sum of the triangles' solid angles over 4 pi at each point (O(F) a point): "
          "float64 (N,)")
      .def(
          "inside",
          [](const PyWinding& w, const Points& points) {
            return per_point<bool>(
                points, [&](const std::array<double, 3>& p) { return w.winding.inside(p); });
          },
          py::arg("points"),
          "Whether the winding number is >= 1/2 at each point (asked again four times as "
          "accurately within 1/4 of the threshold): bool (N,)")
      .def("__repr__", [](const PyWinding& w) {
        return "voxfield.mesh.WindingNumber(vertices=" + std::to_string(w.vertices) +
               ", triangles=" + std::to_string(w.triangles) +
               ", accuracy=" + py::repr(py::float_(w.accuracy)).cast<std::string>() + ")";
      });

  m.def(
      "voxelize_mesh",
      [](const Points& vertices, const Faces& faces, double voxel_size, int padding, int material,
         double accuracy, int threads) {
        if (material < 1 || material > 255)
          throw InvalidArgument("material must be 1..255, not " + std::to_string(material));
        const TriangleMesh mesh = triangle_mesh(vertices, faces);
        MeshVoxelOptions o = voxel_options(voxel_size, padding, accuracy);
        o.material = static_cast<std::uint8_t>(material);
        PythonSignals signals;
        o.interrupter = &signals;
        std::vector<std::uint8_t> materials;
        const Box3i box = without_gil(threads, [&] {
          const World world = voxelize_mesh(mesh, o);
          const Box3i b = *world.voxels.bounds();  // mesh_voxel_box, which the world is bounded by
          materials.resize(static_cast<std::size_t>(b.volume()));
          world.voxels.copy_to_dense(b, materials.data());
          return b;
        });
        return py::make_tuple(fortran(materials, box.size()), triple(box.begin));
      },
      py::arg("vertices"), py::arg("faces"), py::arg("voxel_size"), py::arg("padding") = 2,
      py::arg("material") = 1, py::arg("accuracy") = 2.0, py::arg("threads") = 0,
      "Solid voxels of a triangle mesh, where the generalized winding number at the voxel's centre "
      "is >= 1/2 (so a mesh with holes still fills): (materials uint8 a[i, j, k], first) — "
      "`material` where solid, 0 elsewhere — over the mesh's bounds grown by `padding` voxels; "
      "a[i, j, k] is voxel first + (i, j, k), centred at (first + (i, j, k) + 1/2) * voxel_size");

  m.def(
      "mesh_distance_field",
      [](const Points& vertices, const Faces& faces, double voxel_size, int padding, double band,
         bool is_signed, double max_distance, double accuracy, int threads) {
        const TriangleMesh mesh = triangle_mesh(vertices, faces);
        MeshDistanceOptions o;
        static_cast<MeshVoxelOptions&>(o) = voxel_options(voxel_size, padding, accuracy);
        o.band_voxels = band;
        o.signed_distance = is_signed;
        o.max_distance = max_distance;
        PythonSignals signals;
        o.interrupter = &signals;
        const MeshDistanceField field =
            without_gil(threads, [&] { return mesh_distance_field(mesh, o); });
        return py::make_tuple(fortran(field.values, field.box.size()), triple(field.box.begin));
      },
      py::arg("vertices"), py::arg("faces"), py::arg("voxel_size"), py::arg("padding") = 2,
      py::arg("band") = 3.0, py::arg("signed") = true, py::arg("max_distance") = 0.0,
      py::arg("accuracy") = 2.0, py::arg("threads") = 0,
      "The distance field of a triangle mesh at voxel centres, in the mesh's units: (values "
      "float32 a[i, j, k], first), laid out as voxelize_mesh's. Within `band` voxel edges of the "
      "surface each value is the exact distance to the nearest triangle; beyond it, the distance "
      "to the triangle nearest the closest surface voxel (never below the true distance). "
      "signed: negative where the winding number is >= 1/2; max_distance (0: none) clamps, and "
      "within the band makes a narrow band as OpenVDB's level sets are");
}

}  // namespace voxfield::python
