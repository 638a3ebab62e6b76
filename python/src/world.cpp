// voxfield.world's engine: worlds (materials on a sparse chunked grid, a 256-colour palette) to
// and from NumPy arrays and files (.vox, .npy, .vfw; .vdb written), their exact distance fields
// (every metric, storage, clamp, anisotropic spacing, nearest sites), frames of the DDA ray
// marcher and meshes of their surfaces. The GIL is released
// while voxfield works; Ctrl-C stops a long field (voxfield.Cancelled).
//
// Arrays are indexed a[x, y, z] as voxfield's .npy files and scipy.ndimage's inputs: element
// [i, j, k] is voxel origin + (i, j, k). A world's voxels live in chunks, not in one array, so
// arrays are copies (a view would pin every chunk dense).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstring>
#include <optional>
#include <string>

#include "mesh_arrays.h"
#include "py_world.h"
#include "signals.h"
#include "voxfield/algorithms.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/mesh.h"
#include "voxfield/parallel.h"
#include "voxfield/render.h"
#include "voxfield/world_io.h"

namespace py = pybind11;

namespace voxfield::python {

void bind_edit(py::module_& m, py::class_<PyWorld>& world);  // edit.cpp
void bind_frame(py::class_<PyWorld>& world);                 // world_frame.cpp

DenseField dense_field(const DistanceField& f, bool sites) {
  DenseField d;
  d.size = f.domain.size();
  d.encoding = f.encoding;
  d.origin = f.domain.begin;
  d.with_sites = sites;
  std::visit(
      [&](const auto& g) {
        using T = typename std::decay_t<decltype(g)>::value_type;
        d.width = sizeof(T);
        d.values.resize(static_cast<std::size_t>(f.domain.volume()) * sizeof(T));
        g.copy_to_dense(f.domain, reinterpret_cast<T*>(d.values.data()));
      },
      f.values);
  if (sites) {
    if (!f.sites) throw InvalidArgument("the field keeps no nearest sites");
    std::vector<SiteOffset> s(static_cast<std::size_t>(f.domain.volume()));
    f.sites->copy_to_dense(f.domain, s.data());
    d.sites.resize(3 * s.size());
    std::memcpy(d.sites.data(), s.data(), d.sites.size() * sizeof(std::int16_t));
  }
  return d;
}

py::tuple to_python(const DenseField& f) {
  const Vec3i size = f.size;
  const std::vector<py::ssize_t> shape{size.x, size.y, size.z};
  const auto strides = [&](std::size_t bytes) {  // x fastest: Fortran order
    return std::vector<py::ssize_t>{static_cast<py::ssize_t>(bytes),
                                    static_cast<py::ssize_t>(bytes) * size.x,
                                    static_cast<py::ssize_t>(bytes) * size.x * size.y};
  };
  py::array distances;
  if (f.width == 1)
    distances = py::array_t<std::uint8_t>(shape, strides(1));
  else if (f.width == 2)
    distances = py::array_t<std::uint16_t>(shape, strides(2));
  else
    distances = py::array_t<float>(shape, strides(4));
  std::memcpy(distances.mutable_data(), f.values.data(), f.values.size());
  py::dict info;
  info["scale"] = f.encoding.scale;
  info["bias"] = f.encoding.bias;
  info["origin"] = triple(f.origin);
  if (!f.with_sites) return py::make_tuple(distances, info);
  py::array_t<std::int16_t> s(
      {static_cast<py::ssize_t>(size.x), static_cast<py::ssize_t>(size.y),
       static_cast<py::ssize_t>(size.z), py::ssize_t{3}},
      {py::ssize_t{6}, py::ssize_t{6} * size.x, py::ssize_t{6} * size.x * size.y, py::ssize_t{2}});
  std::memcpy(s.mutable_data(), f.sites.data(), f.sites.size() * sizeof(std::int16_t));
  return py::make_tuple(distances, info, s);
}

namespace {

// A dense x-fastest copy as an array a[x, y, z] (Fortran order: the same bytes).
template <class T>
py::array_t<T> to_array(const std::vector<T>& dense, Vec3i size) {
  py::array_t<T, py::array::f_style> out({size.x, size.y, size.z});
  std::memcpy(out.mutable_data(), dense.data(), dense.size() * sizeof(T));
  return out;
}

std::string world_repr(const PyWorld& w) {
  return reading(w, [&] {
    const Box3i b = w.extent.unite(w.world.voxels.content_bounds());
    return "voxfield.world.World(extent=" + (b.empty() ? std::string("empty") : to_string(b)) +
           ", solid=" + std::to_string(w.world.solid_count()) +
           ", chunk=" + std::to_string(w.world.voxels.chunk_edge()) + ")";
  });
}

}  // namespace

void bind_world(py::module_& parent) {
  py::module_ m = parent.def_submodule("world", "Worlds, their files and their exact fields");
  py::class_<PyWorld> world(m, "World",
                            "Materials on a sparse chunked grid (0 = air) and a 256-entry RGBA "
                            "palette");
  world
      .def(
          py::init([](std::optional<py::array> given, Triple origin, int chunk) {
            auto w = std::make_unique<PyWorld>(World(chunk), Box3i{});
            if (given) {
              if (given->ndim() != 3)
                throw InvalidArgument("materials must be a 3-D array a[x, y, z]");
              const char kind = given->dtype().kind();
              if (kind != 'i' && kind != 'u' && kind != 'b')
                throw InvalidArgument(std::string("materials must be integers 0..255, not a '") +
                                      kind +
                                      "' array (a float volume is meshed by "
                                      "voxfield.mesh.mesh_volume)");
              // The box in 64 bits first: origin + shape must lie in voxfield's range.
              Box3i box;
              for (int a = 0; a < 3; ++a) {
                const std::int64_t lo = origin[static_cast<std::size_t>(a)];
                const std::int64_t hi = lo + given->shape(a);
                if (lo < kCoordRange.begin[a] || hi > kCoordRange.end[a])
                  throw InvalidArgument("materials at origin (" + std::to_string(origin[0]) + ", " +
                                        std::to_string(origin[1]) + ", " +
                                        std::to_string(origin[2]) + ") reach outside " +
                                        to_string(kCoordRange));
                box.begin[a] = static_cast<int>(lo);
                box.end[a] = static_cast<int>(hi);
              }
              w->extent = box;
              const auto values =
                  py::array_t<std::int64_t, py::array::f_style | py::array::forcecast>::ensure(
                      *given);
              std::vector<std::uint8_t> dense(static_cast<std::size_t>(values.size()));
              const std::int64_t* v = values.data();
              for (std::size_t i = 0; i < dense.size(); ++i) {
                if (v[i] < 0 || v[i] > 255)
                  throw InvalidArgument("materials must be 0..255; one is " + std::to_string(v[i]));
                dense[i] = static_cast<std::uint8_t>(v[i]);
              }
              const std::uint8_t* data = dense.data();
              py::gil_scoped_release release;
              w->world.voxels.copy_from_dense(w->extent, data);
              w->world.voxels.compact();
            }
            return w;
          }),
          py::arg("materials") = py::none(), py::arg("origin") = Triple{0, 0, 0},
          py::arg("chunk") = 32,
          "A world from a 3-D array of materials a[x, y, z] (any integer dtype, 0..255; element "
          "[i, j, k] is voxel origin + (i, j, k)), or an empty one; chunk: 8..128, a power of two")
      .def_static(
          "load",
          [](const std::string& path, int chunk, const std::optional<std::string>& grid) {
            LoadOptions o;
            o.chunk_edge = chunk;
            o.vdb_grid = grid.value_or("");
            LoadedWorld in;
            {
              py::gil_scoped_release release;
              in = load_world(path, o);
            }
            return std::make_unique<PyWorld>(std::move(in.world), in.extent);
          },
          py::arg("path"), py::arg("chunk") = 32, py::arg("grid") = py::none(),
          "Reads a .vox, .npy, .vfw or .vdb file (the type from its extension); grid: a .vdb "
          "file's grid to read, by name (default: voxfield's world grid, else the first int32 "
          "grid, else the first); errors name the file")
      .def(
          "save",
          [](const PyWorld& w, const std::string& path) {
            // Said before the file is written (not under the world's lock: a warning handler may
            // be any Python code), so that a warning raised as an error leaves the old file.
            const std::string left_out = reading(w, [&] { return frame_left_out(w.world, path); });
            if (!left_out.empty() && PyErr_WarnEx(PyExc_UserWarning, left_out.c_str(), 1) != 0)
              throw py::error_already_set();
            py::gil_scoped_release release;
            const std::shared_lock read(w.lock);
            save_world(w.world, w.extent, path);
          },
          py::arg("path"),
          "Writes .vox, .npy, .vfw or .vdb (by extension) atomically: a failed save leaves the "
          "old file. A frame .vox and .npy cannot keep is left out with a UserWarning")
      .def_property_readonly(
          "solid_count",
          [](const PyWorld& w) { return reading(w, [&] { return w.world.solid_count(); }); })
      .def_property_readonly(
          "extent",
          [](const PyWorld& w) {
            const Box3i b =
                reading(w, [&] { return w.extent.unite(w.world.voxels.content_bounds()); });
            return py::make_tuple(triple(b.begin), triple(b.end));
          },
          "(begin, end): the volume the file declared united with the content, half-open")
      .def_property_readonly(
          "content_bounds",
          [](const PyWorld& w) {
            const Box3i b = reading(w, [&] { return w.world.voxels.content_bounds(); });
            return py::make_tuple(triple(b.begin), triple(b.end));
          },
          "(begin, end) of the solid voxels, half-open; equal points when there are none")
      .def_property_readonly("chunk", [](const PyWorld& w) { return w.world.voxels.chunk_edge(); })
      .def_property(
          "palette",
          [](const PyWorld& w) {
            const Palette colours = reading(w, [&] { return w.world.palette; });
            py::array_t<std::uint8_t> p({256, 4});
            std::memcpy(p.mutable_data(), colours.data(), 256 * 4);
            return p;
          },
          [](PyWorld& w,
             const py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>& p) {
            if (p.ndim() != 2 || p.shape(0) != 256 || p.shape(1) != 4)
              throw InvalidArgument("palette must be a (256, 4) array of RGBA bytes");
            const std::uint8_t* data = p.data();
            py::gil_scoped_release release;
            const std::unique_lock write(w.lock);
            std::memcpy(w.world.palette.data(), data, 256 * 4);
          },
          "(256, 4) uint8 RGBA; entry m colours material m (entry 0 belongs to air)")
      .def(
          "to_numpy",
          [](const PyWorld& w, std::optional<std::pair<Triple, Triple>> box) {
            Box3i b;
            std::vector<std::uint8_t> dense;
            {
              py::gil_scoped_release release;
              const std::shared_lock read(w.lock);
              b = box_of(w, box);
              if (b.empty()) throw InvalidArgument("to_numpy: the box is empty");
              require_memory(dense_bytes(b, 1), 0, "World.to_numpy",
                             "an array of " + to_string(b.size()) + " voxels");
              dense.resize(static_cast<std::size_t>(b.volume()));
              w.world.voxels.copy_to_dense(b, dense.data());
            }
            return to_array(dense, b.size());
          },
          py::arg("box") = py::none(),
          "The materials of box ((x0, y0, z0), (x1, y1, z1)) (default: the extent) as uint8 "
          "a[x, y, z]")
      .def(
          "fill",
          [](PyWorld& w, Triple begin, Triple end, int material) {
            if (material < 0 || material > 255)
              throw InvalidArgument("material must be 0..255, not " + std::to_string(material));
            const Box3i b{vec3(begin), vec3(end)};
            py::gil_scoped_release release;
            const std::unique_lock write(w.lock);
            w.world.voxels.fill(b, static_cast<std::uint8_t>(material));
          },
          py::arg("begin"), py::arg("end"), py::arg("material"),
          "Sets every voxel of [begin, end) to material (0: air)")
      .def("__repr__", &world_repr);
  bind_edit(m, world);
  bind_frame(world);

  m.def(
      "distance_field",
      [](const PyWorld& w, const std::string& metric, bool is_signed, double max_distance,
         const std::string& storage, std::array<double, 3> spacing, bool sites,
         std::optional<std::pair<Triple, Triple>> box, int threads) {
        DistanceOptions o = field_options(metric, is_signed, max_distance, storage, spacing, sites);
        PythonSignals signals;
        o.interrupter = &signals;
        DenseField dense;
        {
          py::gil_scoped_release release;
          const std::shared_lock read(w.lock);
          std::optional<ThreadLimit> limit;
          if (threads > 0) limit.emplace(threads);
          dense = dense_field(
              compute_distance_field(w.world, with_domain(o, w, box, "distance_field")), sites);
        }
        return to_python(dense);
      },
      py::arg("world"), py::arg("metric") = "euclidean", py::arg("signed") = false,
      py::arg("max_distance") = 0.0, py::arg("storage") = "f32",
      py::arg("spacing") = std::array<double, 3>{1, 1, 1}, py::arg("sites") = false,
      py::arg("box") = py::none(), py::arg("threads") = 0, "See voxfield.world.distance_field");

  m.def(
      "approximate",
      [](const PyWorld& w, const std::string& algorithm, const std::string& metric, bool is_signed,
         double max_distance, const std::string& storage, std::array<double, 3> spacing,
         OptionalBox box, OptionalBox focus, int threads) {
        const DistanceOptions options =
            field_options(metric, is_signed, max_distance, storage, spacing, false);
        AlgorithmOptions a;
        a.algorithm = parse_algorithm(algorithm);
        if (focus) a.focus = Box3i{vec3(focus->first), vec3(focus->second)};
        DenseField dense;
        AlgorithmStats st;
        FieldError e;
        {
          py::gil_scoped_release release;
          const std::shared_lock read(w.lock);
          std::optional<ThreadLimit> limit;
          if (threads > 0) limit.emplace(threads);
          const DistanceOptions o = with_domain(options, w, box, "approximate");
          const DistanceField approx = compute_distance_field(w.world, o, a, &st);
          e = compare_fields(approx, compute_distance_field(w.world, o), w.world);
          dense = dense_field(approx, false);
        }
        py::dict report;
        report["ms"] = st.ms;
        report["passes"] = st.passes;
        report["iterations"] = st.iterations;
        report["updates"] = st.updates;
        report["voxels"] = e.voxels;
        report["air_voxels"] = e.air_voxels;
        report["wrong"] = e.wrong;
        report["too_large"] = e.too_large;
        report["too_small"] = e.too_small;
        report["max_over"] = e.max_over;
        report["max_under"] = e.max_under;
        report["percent_wrong"] = e.percent_wrong();
        report["percent_unsafe"] = e.percent_unsafe();
        return py::make_tuple(to_python(dense), report);
      },
      py::arg("world"), py::arg("algorithm") = "jfa", py::arg("metric") = "euclidean",
      py::arg("signed") = false, py::arg("max_distance") = 0.0, py::arg("storage") = "f32",
      py::arg("spacing") = std::array<double, 3>{1, 1, 1}, py::arg("box") = py::none(),
      py::arg("focus") = py::none(), py::arg("threads") = 0, "See voxfield.world.approximate");

  m.def(
      "render",
      [](const PyWorld& w, int width, int height, const std::string& camera,
         const std::string& view, bool shadows, bool ambient_occlusion, double fog,
         const std::string& metric, int threads, const std::string& camera_frame) {
        if (camera_frame != "voxels" && camera_frame != "world")
          throw InvalidArgument("render: camera_frame is \"voxels\" or \"world\", not \"" +
                                camera_frame + "\"");
        RenderSceneOptions so;
        so.skip_metric = parse_metric(metric);
        so.lighting_field = shadows || ambient_occlusion;
        RenderOptions o;
        o.width = width;
        o.height = height;
        o.view = parse_render_view(view);
        o.soft_shadows = shadows;
        o.ambient_occlusion = ambient_occlusion;
        o.fog_density = fog;
        const double aspect = static_cast<double>(width) / std::max(1, height);
        PythonSignals signals;
        Image image;
        {
          py::gil_scoped_release release;
          std::optional<ThreadLimit> limit;
          if (threads > 0) limit.emplace(threads);
          const std::shared_lock read(w.lock);
          const Box3i extent = w.extent.unite(w.world.voxels.content_bounds());
          if (extent.empty()) throw InvalidArgument("render: the world holds no volume");
          // As the CLI: automatic cameras frame the content, within the extent.
          const Box3i content = w.world.voxels.content_bounds().intersect(extent);
          const Camera cam =
              Camera::parse(camera, camera == "top" || content.empty() ? extent : content, aspect,
                            camera_frame == "world" ? &w.world.frame : nullptr);
          const RenderScene scene(w.world, so, extent);
          image = voxfield::render(scene, cam, o, nullptr, &signals);
        }
        py::array_t<std::uint8_t> out({image.height, image.width, 3});
        std::memcpy(out.mutable_data(), image.rgb.data(), image.rgb.size());
        return out;
      },
      py::arg("world"), py::arg("width") = 640, py::arg("height") = 360, py::arg("camera") = "auto",
      py::arg("view") = "shaded", py::arg("shadows") = true, py::arg("ambient_occlusion") = true,
      py::arg("fog") = 0.0, py::arg("metric") = "manhattan", py::arg("threads") = 0,
      py::arg("camera_frame") = "voxels", "See voxfield.world.render");

  m.def(
      "mesh",
      [](const PyWorld& w, const std::string& algorithm, double iso, const std::string& metric,
         int chunk, int threads) {
        MeshOptions o = world_mesh_options(algorithm, iso, chunk);
        const Metric mt = parse_metric(metric);
        PythonSignals signals;
        o.interrupter = &signals;
        const Mesh mesh = without_gil(threads, [&] {
          const std::shared_lock read(w.lock);
          return mesh_world(w.world, o, mt);
        });
        return to_arrays(mesh, true);
      },
      py::arg("world"), py::arg("algorithm") = "mc", py::arg("iso") = 0.0,
      py::arg("metric") = "euclidean", py::arg("chunk") = 32, py::arg("threads") = 0,
      "See voxfield.world.mesh");
}

}  // namespace voxfield::python
