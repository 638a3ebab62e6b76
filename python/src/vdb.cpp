// voxfield.vdb's engine: the grids of an OpenVDB file as read by voxfield's own parser
// (voxfield/vdb.h), their values and activity over a box as NumPy arrays a[x, y, z] (element
// [i, j, k] is voxel box.begin + (i, j, k), as voxfield.world's arrays and pyopenvdb's
// copyToArray), their transforms and metadata. The GIL is released while the file is read.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <memory>
#include <optional>
#include <string>

#include "py_world.h"
#include "voxfield/error.h"
#include "voxfield/vdb.h"

namespace py = pybind11;

namespace voxfield::python {
namespace {

using Grid = std::shared_ptr<VdbGrid>;

Box3i box_or_active(const VdbGrid& g, const OptionalBox& box, const char* who) {
  const Box3i b = box ? Box3i{vec3(box->first), vec3(box->second)} : g.active_bounds();
  if (b.empty())
    throw InvalidArgument(std::string(who) + ": the box is empty" +
                          (box ? "" : " (the grid has no active voxel: pass a box)"));
  return b;
}

// x-fastest values, `components` per voxel, as an array a[x, y, z(, c)] of T.
template <class T>
py::array values_array(const std::vector<double>& dense, Vec3i size, int components) {
  const auto n = static_cast<py::ssize_t>(sizeof(T));
  const py::ssize_t c = components;
  std::vector<py::ssize_t> shape{size.x, size.y, size.z};
  std::vector<py::ssize_t> strides{n * c, n * c * size.x, n * c * size.x * size.y};
  if (components > 1) {
    shape.push_back(c);
    strides.push_back(n);
  }
  py::array_t<T> out(shape, strides);
  T* p = out.mutable_data();
  for (std::size_t i = 0; i < dense.size(); ++i) p[i] = static_cast<T>(dense[i]);
  return out;
}

py::object metadata_value(const VdbMetadata& m) {
  if (m.type == "string") return py::str(m.text);
  if (m.numbers.size() == 1) {
    if (m.type == "bool") return py::bool_(m.numbers[0] != 0);
    if (m.type == "int32" || m.type == "int64")
      return py::int_(static_cast<long long>(m.numbers[0]));
    return py::float_(m.numbers[0]);
  }
  if (!m.numbers.empty()) {
    py::tuple t(m.numbers.size());
    const bool ints = m.type.size() == 5 && m.type.back() == 'i';  // vec2i, vec3i, vec4i
    for (std::size_t i = 0; i < m.numbers.size(); ++i)
      t[i] = ints ? py::object(py::int_(static_cast<long long>(m.numbers[i])))
                  : py::object(py::float_(m.numbers[i]));
    return t;
  }
  return py::none();  // a type voxfield does not decode
}

std::string grid_repr(const VdbGrid& g) {
  const Box3i b = g.active_bounds();
  return "voxfield.vdb.Grid(name='" + g.name + "', type=" + vdb_value_type_name(g.value_type) +
         ", class='" + g.grid_class + "', active=" + (b.empty() ? "empty" : to_string(b)) +
         ", leaves=" + std::to_string(g.leaves.size()) +
         ", tiles=" + std::to_string(g.tiles.size()) + ")";
}

}  // namespace

void bind_vdb(py::module_& parent) {
  py::module_ m = parent.def_submodule("vdb", "OpenVDB files read by voxfield's own parser");
  py::class_<VdbGrid, Grid>(m, "Grid", "One grid of a .vdb file (read-only)")
      .def_property_readonly("name", [](const VdbGrid& g) { return g.name; })
      .def_property_readonly(
          "value_type",
          [](const VdbGrid& g) { return std::string(vdb_value_type_name(g.value_type)); },
          "'float', 'double', 'bool', 'int32' or 'vec3s'")
      .def_property_readonly(
          "grid_class", [](const VdbGrid& g) { return g.grid_class; },
          "'level set', 'fog volume', 'staggered' or 'unknown'")
      .def_property_readonly(
          "half_float", [](const VdbGrid& g) { return g.half_float; },
          "whether the file stores its values as 16-bit halves")
      .def_property_readonly(
          "instance_of", [](const VdbGrid& g) { return g.instance_of; },
          "the grid whose tree this one shares ('' for none)")
      .def_property_readonly(
          "index_to_world",
          [](const VdbGrid& g) {
            py::array_t<double> a({3, 4});
            std::memcpy(a.mutable_data(), g.index_to_world.data(), sizeof(double) * 12);
            return a;
          },
          "(3, 4) float64: world = m @ (i, j, k, 1), in the file's world units")
      .def_property_readonly(
          "voxel_size",
          [](const VdbGrid& g) {
            return py::make_tuple(g.voxel_size[0], g.voxel_size[1], g.voxel_size[2]);
          },
          "world units per index step along x, y, z")
      .def_property_readonly(
          "background",
          [](const VdbGrid& g) -> py::object {
            if (g.components == 3)
              return py::make_tuple(g.background[0], g.background[1], g.background[2]);
            if (g.value_type == VdbValueType::kBool) return py::bool_(g.background[0] != 0);
            if (g.value_type == VdbValueType::kInt32)
              return py::int_(static_cast<long long>(g.background[0]));
            return py::float_(g.background[0]);
          },
          "the value of every voxel the tree does not store")
      .def_property_readonly(
          "metadata",
          [](const VdbGrid& g) {
            py::dict d;
            for (const auto& [key, value] : g.metadata) d[py::str(key)] = metadata_value(value);
            return d;
          },
          "the grid's metadata: str, int, float, bool or tuples of numbers (None: not decoded)")
      .def_property_readonly(
          "active_bounds", [](const VdbGrid& g) { return box_tuple(g.active_bounds()); },
          "((x0, y0, z0), (x1, y1, z1)) around the active voxels, end exclusive; None if none")
      .def_property_readonly(
          "stored_bounds", [](const VdbGrid& g) { return box_tuple(g.stored_bounds()); },
          "the box around every tile and leaf the tree stores; None if none")
      .def_property_readonly("leaf_count", [](const VdbGrid& g) { return g.leaves.size(); })
      .def_property_readonly("tile_count", [](const VdbGrid& g) { return g.tiles.size(); })
      .def(
          "to_numpy",
          [](const VdbGrid& g, OptionalBox box) {
            const Box3i b = box_or_active(g, box, "Grid.to_numpy");
            std::vector<double> dense;
            {
              py::gil_scoped_release release;
              dense = g.dense(b);
            }
            switch (g.value_type) {
              case VdbValueType::kFloat:
              case VdbValueType::kVec3f:
                return values_array<float>(dense, b.size(), g.components);
              case VdbValueType::kDouble:
                return values_array<double>(dense, b.size(), 1);
              case VdbValueType::kBool:
                return values_array<bool>(dense, b.size(), 1);
              case VdbValueType::kInt32:
                return values_array<std::int32_t>(dense, b.size(), 1);
            }
            throw InvalidArgument("Grid.to_numpy: unknown value type");
          },
          py::arg("box") = py::none(),
          "The values over box ((x0, y0, z0), (x1, y1, z1)) (default: the active bounds) as "
          "a[x, y, z] (a[x, y, z, 3] for vec3s): float32, float64, bool or int32")
      .def(
          "active_mask",
          [](const VdbGrid& g, OptionalBox box) {
            const Box3i b = box_or_active(g, box, "Grid.active_mask");
            std::vector<std::uint8_t> dense;
            {
              py::gil_scoped_release release;
              dense = g.dense_active(b);
            }
            py::array_t<bool, py::array::f_style> out({b.size().x, b.size().y, b.size().z});
            std::memcpy(out.mutable_data(), dense.data(), dense.size());
            return out;
          },
          py::arg("box") = py::none(), "Whether each voxel over box is active, bool a[x, y, z]")
      .def("__repr__", &grid_repr);

  m.def(
      "read",
      [](const std::string& path, std::uint64_t memory_limit) {
        VdbFile file;
        {
          py::gil_scoped_release release;
          VdbReadOptions o;
          o.memory_limit_bytes = memory_limit;
          file = read_vdb(path, o);
        }
        py::list grids;
        for (VdbGrid& g : file.grids) grids.append(std::make_shared<VdbGrid>(std::move(g)));
        return grids;
      },
      py::arg("path"), py::arg("memory_limit") = 0,
      "The grids of a .vdb file (float, double, bool, int32 and vec3s; others are skipped) in the "
      "file's order. Raises FormatError naming the file and byte offset for a damaged file, "
      "ResourceLimitError past memory_limit bytes (0: the process default).");
}

}  // namespace voxfield::python
