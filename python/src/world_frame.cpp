// voxfield.world's frames: where a World's voxels sit in the world (voxel_frame.h) — the origin,
// the voxel size and the rotation as properties, and points carried between voxel and world
// coordinates as (N, 3) arrays.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>

#include "py_world.h"
#include "voxfield/error.h"
#include "voxfield/voxel_frame.h"

namespace py = pybind11;

namespace voxfield::python {
namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

py::tuple as_tuple(Vec3d v) {
  return py::make_tuple(v.x, v.y, v.z);
}
Vec3d as_vec(const std::array<double, 3>& a) {
  return {a[0], a[1], a[2]};
}

// Changes the world's frame under the write lock — read, changed and written in one hold, so two
// threads setting different parts keep both — refusing (ValueError) what validate refuses and
// keeping the frame it had then.
template <class Change>
void change_frame(PyWorld& w, Change&& change) {
  py::gil_scoped_release release;
  const std::unique_lock write(w.lock);
  VoxelFrame f = w.world.frame;
  change(f);
  f.validate("World.frame");
  w.world.frame = f;
}

// (N, 3) points through `map`, a frame method.
py::array_t<double> map_points(const PyWorld& w, const Doubles& points, const char* what,
                               Vec3d (VoxelFrame::*map)(Vec3d) const) {
  if (points.ndim() != 2 || points.shape(1) != 3)
    throw InvalidArgument(std::string(what) + ": points must be an (N, 3) array");
  const VoxelFrame f = reading(w, [&] { return w.world.frame; });
  const auto n = static_cast<std::size_t>(points.shape(0));
  py::array_t<double> out({points.shape(0), py::ssize_t{3}});
  const double* in = points.data();
  double* o = out.mutable_data();
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < n; ++i) {
      const Vec3d p = (f.*map)({in[3 * i], in[3 * i + 1], in[3 * i + 2]});
      o[3 * i] = p.x;
      o[3 * i + 1] = p.y;
      o[3 * i + 2] = p.z;
    }
  }
  return out;
}

}  // namespace

void bind_frame(py::class_<PyWorld>& world) {
  world
      .def_property(
          "origin_world",
          [](const PyWorld& w) {
            return as_tuple(reading(w, [&] { return w.world.frame; }).origin_world);
          },
          [](PyWorld& w, const std::array<double, 3>& v) {
            change_frame(w, [&](VoxelFrame& f) { f.origin_world = as_vec(v); });
          },
          "(x, y, z): where voxel coordinate (0, 0, 0), a voxel's corner, lies in the world")
      .def_property(
          "voxel_size_world",
          [](const PyWorld& w) {
            return as_tuple(reading(w, [&] { return w.world.frame; }).voxel_size_world);
          },
          [](PyWorld& w, const std::array<double, 3>& v) {
            change_frame(w, [&](VoxelFrame& f) { f.voxel_size_world = as_vec(v); });
          },
          "(sx, sy, sz): a voxel's edge along each of its axes in world units, > 0")
      .def_property(
          "rotation",
          [](const PyWorld& w) {
            const VoxelFrame f = reading(w, [&] { return w.world.frame; });
            py::array_t<double> r({3, 3});
            for (int row = 0; row < 3; ++row)
              for (int c = 0; c < 3; ++c) r.mutable_at(row, c) = f.rotation[row][c];
            return r;
          },
          [](PyWorld& w, const Doubles& r) {
            if (r.ndim() != 2 || r.shape(0) != 3 || r.shape(1) != 3)
              throw InvalidArgument("World.rotation must be a (3, 3) array");
            std::array<Vec3d, 3> rows;  // copied while the GIL is held
            for (int row = 0; row < 3; ++row)
              for (int c = 0; c < 3; ++c) rows[row][c] = r.at(row, c);
            change_frame(w, [&](VoxelFrame& f) { f.rotation = rows; });
          },
          "(3, 3): the rotation from the voxel axes to the world's (orthonormal, det +1)")
      .def(
          "to_world",
          [](const PyWorld& w, const Doubles& points) {
            return map_points(w, points, "World.to_world", &VoxelFrame::world_from_vox);
          },
          py::arg("points_vox"),
          "(N, 3) voxel coordinates (voxel (i, j, k) spans [i, i+1)^3) to world coordinates: "
          "origin_world + rotation @ (voxel_size_world * p)")
      .def(
          "to_voxels",
          [](const PyWorld& w, const Doubles& points) {
            return map_points(w, points, "World.to_voxels", &VoxelFrame::vox_from_world);
          },
          py::arg("points_world"), "(N, 3) world coordinates to voxel coordinates");
}

}  // namespace voxfield::python
