// voxfield.csg's engine: CSG models (docs/csg.md) from Python — parsed from text or files,
// evaluated at NumPy points, voxelised into NumPy arrays, compiled into octrees and meshed. The
// GIL is released while the C++ works.
//
// Arrays: points are float64 (N, 3) in model units; voxel arrays are indexed a[i, j, k] with i
// along x, as voxfield's .npy files are (Fortran order, no copy).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <optional>
#include <span>

#include "mesh_arrays.h"
#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"
#include "voxfield/csg_files.h"
#include "voxfield/csg_mesh.h"
#include "voxfield/file.h"
#include "voxfield/parallel.h"

namespace py = pybind11;

namespace voxfield::python {
namespace {

using Points = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::optional<csg::Bounds> to_bounds(const std::optional<std::vector<double>>& box) {
  if (!box) return std::nullopt;
  if (box->size() != 6) throw InvalidArgument("box takes six numbers: (x0, y0, z0, x1, y1, z1)");
  const csg::Bounds b{{(*box)[0], (*box)[1], (*box)[2]}, {(*box)[3], (*box)[4], (*box)[5]}};
  if (b.empty()) throw InvalidArgument("box: each of x1, y1, z1 must be at least x0, y0, z0");
  return b;
}

std::vector<Vec3d> read_points(const Points& points) {
  if (points.ndim() != 2 || points.shape(1) != 3)
    throw InvalidArgument("points must be an array of shape (N, 3)");
  std::vector<Vec3d> out(static_cast<std::size_t>(points.shape(0)));
  const double* p = points.data();
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
  return out;
}

}  // namespace

void bind_csg(py::module_& parent) {
  py::module_ m = parent.def_submodule("csg", "CSG models: the voxel compiler (docs/csg.md)");
  py::class_<csg::Model>(m, "Model",
                         "A CSG model: an S-expression or JSON text, or an OpenSCAD .csg file")
      .def(
          py::init([](const std::string& text, const std::string& name) {
            return csg::parse_model(text, name);
          }),
          py::arg("text"), py::arg("name") = "model.sdf",
          "Parses the model language (JSON when the text starts with '[', S-expressions otherwise)")
      .def_static(
          "load",
          [](const std::string& path, bool facets) {
            csg::OpenScadOptions o;
            o.facets = facets;
            return csg::load_model(path, o);
          },
          py::arg("path"), py::arg("facets") = false,
          "Reads .sdf, .json or OpenSCAD .csg (facets: OpenSCAD's polytopes for spheres and "
          "cylinders)")
      .def_property_readonly("nodes",
                             [](const csg::Model& mo) { return csg::model_info(mo).nodes; })
      .def_property_readonly("unique_nodes",
                             [](const csg::Model& mo) { return csg::model_info(mo).unique_nodes; })
      .def_property_readonly("shapes",
                             [](const csg::Model& mo) { return csg::model_info(mo).shapes; })
      .def_property_readonly("label",
                             [](const csg::Model& mo) {
                               return std::string(csg::label_name(csg::label_of(mo, mo.root)));
                             })
      .def_property_readonly(
          "bounds",
          [](const csg::Model& mo) -> py::object {
            const auto b = csg::model_bounds(mo);
            if (!b) return py::none();
            return py::make_tuple(py::make_tuple(b->lo.x, b->lo.y, b->lo.z),
                                  py::make_tuple(b->hi.x, b->hi.y, b->hi.z));
          },
          "((x0, y0, z0), (x1, y1, z1)) containing the solid, or None when unbounded")
      .def_property_readonly(
          "palette",
          [](const csg::Model& mo) {
            py::array_t<std::uint8_t> p({256, 4});
            for (int i = 0; i < 256; ++i) {
              const Rgba c = mo.palette[static_cast<std::size_t>(i)];
              std::uint8_t* row = p.mutable_data(i);
              row[0] = c.r, row[1] = c.g, row[2] = c.b, row[3] = c.a;
            }
            return p;
          },
          "RGBA per material (256 x 4 uint8)")
      .def(
          "evaluate",
          [](const csg::Model& mo, const Points& points) {
            const std::vector<Vec3d> pts = read_points(points);
            std::vector<double> values(pts.size());
            {
              py::gil_scoped_release release;
              const csg::Tape tape = csg::compile_tape(mo);
              parallel_for(pts.size(), 4096, [&](std::size_t b, std::size_t e) {
                csg::evaluate(tape, std::span(pts).subspan(b, e - b),
                              std::span(values).subspan(b, e - b));
              });
            }
            return py::array_t<double>(static_cast<py::ssize_t>(values.size()), values.data());
          },
          py::arg("points"),
          "The model's value at each point of a float64 (N, 3) array: float64 (N,)")
      .def(
          "materials",
          [](const csg::Model& mo, const Points& points) {
            const std::vector<Vec3d> pts = read_points(points);
            std::vector<double> values(pts.size());
            std::vector<std::uint8_t> mats(pts.size());
            {
              py::gil_scoped_release release;
              const csg::Tape tape = csg::compile_tape(mo);
              csg::evaluate(tape, pts, values, mats);
            }
            return py::array_t<std::uint8_t>(static_cast<py::ssize_t>(mats.size()), mats.data());
          },
          py::arg("points"),
          "The material at each point (meaningful where the value is <= 0): uint8 (N,)")
      .def(
          "voxelize",
          [](const csg::Model& mo, double voxel_size, std::optional<std::vector<double>> box,
             std::optional<double> max_distance, bool field) {
            csg::VoxelizeOptions o;
            o.voxel_size = voxel_size;
            o.box = to_bounds(box);
            if (max_distance) o.max_distance = *max_distance;
            o.field = field;
            std::vector<std::uint8_t> mats;
            csg::Voxelized v;
            {
              py::gil_scoped_release release;
              v = csg::voxelize(mo, o);
              mats.resize(static_cast<std::size_t>(Box3i::from_size(v.dims).volume()));
              v.world.voxels.copy_to_dense(Box3i::from_size(v.dims), mats.data());
            }
            py::array materials = fortran(mats, v.dims);
            if (!field) return py::object(materials);
            return py::object(py::make_tuple(materials, fortran(v.field, v.dims)));
          },
          py::arg("voxel_size"), py::arg("box") = py::none(), py::arg("max_distance") = py::none(),
          py::arg("field") = false,
          "uint8 materials a[i, j, k] of the voxels whose centre box.min + (i, j, k, + 1/2) * "
          "voxel_size "
          "has a value <= 0; with field=True also the float32 values there")
      .def(
          "octree",
          [](const csg::Model& mo, int depth) {
            csg::Octree t;
            {
              py::gil_scoped_release release;
              csg::OctreeOptions o;
              o.depth = depth;
              t = csg::build_octree(csg::compile_tape(mo), mo, o);
            }
            const csg::CompileStats& s = t.stats;
            py::dict d;
            d["cells_visited"] = s.cells_visited, d["leaves"] = s.leaves, d["empty"] = s.empty,
            d["full"] = s.full;
            d["surface"] = s.surface, d["variants"] = s.variants, d["whole_nodes"] = s.whole_nodes;
            d["mean_nodes"] = s.mean_nodes, d["max_nodes"] = s.max_nodes,
            d["octree_ms"] = s.octree_ms;
            return d;
          },
          py::arg("depth") = 6, "Builds the octree of pruned tapes; returns its figures")
      .def(
          "mesh",
          [](const csg::Model& mo, double voxel_size, const std::string& algorithm,
             std::optional<std::vector<double>> box) {
            CsgMeshOptions o;
            o.voxel_size = voxel_size;
            o.box = to_bounds(box);
            o.mesh.algorithm = parse_mesher(algorithm);
            Mesh mesh;
            {
              py::gil_scoped_release release;
              mesh = mesh_csg(mo, o);
            }
            const auto nv = static_cast<py::ssize_t>(mesh.positions.size());
            py::array_t<float> vertices({nv, py::ssize_t{3}}), normals({nv, py::ssize_t{3}});
            py::array_t<std::uint8_t> colors({nv, py::ssize_t{3}});
            py::array_t<std::uint32_t> faces(
                {static_cast<py::ssize_t>(mesh.triangle_count()), py::ssize_t{3}});
            std::memcpy(vertices.mutable_data(), mesh.positions.data(),
                        mesh.positions.size() * sizeof(float) * 3);
            std::memcpy(normals.mutable_data(), mesh.normals.data(),
                        mesh.normals.size() * sizeof(float) * 3);
            std::memcpy(colors.mutable_data(), mesh.colors.data(), mesh.colors.size() * 3);
            std::memcpy(faces.mutable_data(), mesh.indices.data(),
                        mesh.indices.size() * sizeof(std::uint32_t));
            return py::make_tuple(vertices, faces, normals, colors);
          },
          py::arg("voxel_size"), py::arg("algorithm") = "dc", py::arg("box") = py::none(),
          "The surface as (vertices float32 (V, 3), faces uint32 (F, 3) counter-clockwise from "
          "outside, "
          "normals float32 (V, 3), colors uint8 (V, 3)); algorithm 'dc', 'mc' or 'sn'");
  m.def(
      "translate_openscad",
      [](const std::string& text, const std::string& name, bool facets) {
        csg::OpenScadOptions o;
        o.facets = facets;
        return csg::translate_openscad_csg(text, name, o);
      },
      py::arg("text"), py::arg("name") = "model.csg", py::arg("facets") = false,
      "OpenSCAD's .csg text translated into the model language");
  py::register_exception<csg::ModelError>(m, "ModelError", PyExc_ValueError);
}

}  // namespace voxfield::python
