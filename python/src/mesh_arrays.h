// NumPy arrays of voxfield's results, shared by the extension's modules: meshes, and volumes in
// Fortran order.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstring>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/mesh.h"

namespace voxfield::python {

// (vertices float32 (V, 3), faces uint32 (F, 3), normals float32 (V, 3)[, colors uint8 (V, 3)]).
inline pybind11::tuple to_arrays(const Mesh& mesh, bool with_colors) {
  const auto nv = static_cast<pybind11::ssize_t>(mesh.positions.size());
  pybind11::array_t<float> vertices({nv, pybind11::ssize_t{3}}),
      normals({nv, pybind11::ssize_t{3}});
  pybind11::array_t<std::uint32_t> faces(
      {static_cast<pybind11::ssize_t>(mesh.triangle_count()), pybind11::ssize_t{3}});
  std::memcpy(vertices.mutable_data(), mesh.positions.data(), mesh.positions.size() * 12);
  std::memcpy(normals.mutable_data(), mesh.normals.data(), mesh.normals.size() * 12);
  std::memcpy(faces.mutable_data(), mesh.indices.data(), mesh.indices.size() * 4);
  if (!with_colors) return pybind11::make_tuple(vertices, faces, normals);
  pybind11::array_t<std::uint8_t> colors({nv, pybind11::ssize_t{3}});
  if (!mesh.colors.empty())
    std::memcpy(colors.mutable_data(), mesh.colors.data(), mesh.colors.size() * 3);
  return pybind11::make_tuple(vertices, faces, normals, colors);
}

// A Fortran-ordered array of `dims` over a copy of `values` (x fastest): a[i, j, k] is element
// i + dims.x * (j + dims.y * k).
template <class T>
pybind11::array_t<T> fortran(const std::vector<T>& values, Vec3i dims) {
  pybind11::array_t<T, pybind11::array::f_style> out({dims.x, dims.y, dims.z});
  if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
  return out;
}

}  // namespace voxfield::python
