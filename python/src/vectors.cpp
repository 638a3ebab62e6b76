// voxfield.vectors's engine: dynamic vector-field volume textures (docs/vectors.md) from Python —
// a box in world space, sources as NumPy rows, one generation or a simulation stepped over frames
// (decay and blend), sampling, and the visualiser's picture. The GIL is released while the C++
// works; Ctrl-C stops a generation (voxfield.Cancelled).
//
// Arrays: sources are float64 (N, 4) rows (x, y, z, radius) of stationary sources or (N, 7) rows
// (x, y, z, previous x, y, z, radius) of moving ones; a texture comes back decoded as float32
// a[i, j, k, c] with i along the box's x axis and c = (direction x, y, z in world space,
// strength), as the CLI's .npy output.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <vector>

#include "signals.h"
#include "voxfield/error.h"
#include "voxfield/vectors.h"

namespace py = pybind11;

namespace voxfield::python {
namespace {

using Rows = py::array_t<double, py::array::c_style | py::array::forcecast>;

std::vector<VectorSource> read_sources(const Rows& rows) {
  if (rows.ndim() != 2 || (rows.shape(1) != 4 && rows.shape(1) != 7))
    throw InvalidArgument(
        "sources must be an array of shape (N, 4): x, y, z, radius, or (N, 7): x, y, z, "
        "previous x, y, z, radius");
  const bool moving = rows.shape(1) == 7;
  std::vector<VectorSource> out(static_cast<std::size_t>(rows.shape(0)));
  for (py::ssize_t i = 0; i < rows.shape(0); ++i) {
    VectorSource& s = out[static_cast<std::size_t>(i)];
    s.position = {rows.at(i, 0), rows.at(i, 1), rows.at(i, 2)};
    s.previous = moving ? Vec3d{rows.at(i, 3), rows.at(i, 4), rows.at(i, 5)} : s.position;
    s.radius = rows.at(i, moving ? 6 : 3);
  }
  validate_sources(out);
  return out;
}

Vec3d vec3_arg(const std::vector<double>& v, const char* what) {
  if (v.size() != 3) throw InvalidArgument(std::string(what) + " takes three numbers");
  return {v[0], v[1], v[2]};
}

// The decoded texels, a[i, j, k, c] with x fastest in memory and the channels innermost.
py::array_t<float> decoded(const VectorTexture& t) {
  const Vec3i n = t.resolution();
  const auto f = static_cast<py::ssize_t>(sizeof(float));
  py::array_t<float> out({py::ssize_t{n.x}, py::ssize_t{n.y}, py::ssize_t{n.z}, py::ssize_t{4}},
                         {4 * f, 4 * f * n.x, 4 * f * n.x * n.y, f});
  float* p = out.mutable_data();
  for (std::int64_t i = 0; i < t.voxel_count(); ++i) {
    const VectorTexel v = t.get(i);
    p[4 * i] = v.x, p[4 * i + 1] = v.y, p[4 * i + 2] = v.z, p[4 * i + 3] = v.strength;
  }
  return out;
}

// Samples of `texture` at world points (N, 3): float64 (N, 4) rows (vector x, y, z — direction
// times strength — and strength), zero outside the box.
py::array_t<double> sample_points(const VectorVolume& volume, const VectorTexture& texture,
                                  const Rows& points) {
  if (points.ndim() != 2 || points.shape(1) != 3)
    throw InvalidArgument("points must be an array of shape (N, 3)");
  py::array_t<double> out({points.shape(0), py::ssize_t{4}});
  for (py::ssize_t i = 0; i < points.shape(0); ++i) {
    const VectorSample s =
        sample_vectors(volume, texture, {points.at(i, 0), points.at(i, 1), points.at(i, 2)});
    const Vec3d v = s.vector();
    out.mutable_at(i, 0) = v.x, out.mutable_at(i, 1) = v.y, out.mutable_at(i, 2) = v.z;
    out.mutable_at(i, 3) = s.strength;
  }
  return out;
}

// A simulation shared by Python threads: step() releases the GIL while it writes the textures, so
// it takes the lock alone and the readers share it — each after releasing the GIL, so a thread
// waiting for the lock never holds the GIL.
struct PySimulation {
  VectorSimulation sim;
  mutable std::shared_mutex lock;
  PySimulation(const VectorVolume& v, VectorStorage s, VectorOptions o, double decay)
      : sim(v, s, o, decay) {}
};

// A reader's copy of a texture, taken under the lock.
VectorTexture copy_of(const PySimulation& s,
                      const VectorTexture& (VectorSimulation::*which)() const) {
  py::gil_scoped_release release;
  std::shared_lock read(s.lock);
  return (s.sim.*which)();
}

VectorOptions vector_options(const std::string& algorithm, const std::string& rule) {
  VectorOptions o;
  o.algorithm = parse_vector_algorithm(algorithm);
  o.rule = parse_vector_rule(rule);
  return o;
}

}  // namespace

void bind_vectors(py::module_& parent) {
  py::module_ m =
      parent.def_submodule("vectors", "Dynamic vector-field volume textures (docs/vectors.md)");
  py::class_<VectorVolume>(m, "Volume", "An oriented box in world space and its resolution")
      .def(py::init([](std::vector<double> centre, std::vector<double> size,
                       std::vector<int> resolution, double rotation_degrees,
                       std::vector<double> rotation_axis) {
             VectorVolume v;
             v.centre = vec3_arg(centre, "centre");
             v.size = vec3_arg(size, "size");
             if (resolution.size() != 3) throw InvalidArgument("resolution takes three integers");
             v.resolution = {resolution[0], resolution[1], resolution[2]};
             if (rotation_degrees != 0)
               v.rotation =
                   VectorVolume::rotation_about(rotation_degrees, vec3_arg(rotation_axis, "axis"));
             v.validate();
             return v;
           }),
           py::arg("centre") = std::vector<double>{0, 0, 0},
           py::arg("size") = std::vector<double>{1, 1, 1},
           py::arg("resolution") = std::vector<int>{64, 64, 64}, py::arg("rotation_degrees") = 0.0,
           py::arg("rotation_axis") = std::vector<double>{0, 0, 1},
           "centre and size (full extents) in world units, resolution (nx, ny, nz), and a rotation "
           "of the box by rotation_degrees about rotation_axis")
      .def_property_readonly("resolution",
                             [](const VectorVolume& v) {
                               return py::make_tuple(v.resolution.x, v.resolution.y,
                                                     v.resolution.z);
                             })
      .def(
          "voxel_centre",
          [](const VectorVolume& v, int i, int j, int k) {
            const Vec3d p = v.voxel_centre(i, j, k);
            return py::make_tuple(p.x, p.y, p.z);
          },
          py::arg("i"), py::arg("j"), py::arg("k"), "World position of voxel (i, j, k)'s centre")
      .def("__repr__", [](const VectorVolume& v) {
        return "voxfield.vectors.Volume(resolution=(" + std::to_string(v.resolution.x) + ", " +
               std::to_string(v.resolution.y) + ", " + std::to_string(v.resolution.z) + "))";
      });

  m.def(
      "generate",
      [](const VectorVolume& volume, const Rows& sources, const std::string& algorithm,
         const std::string& rule, const std::string& storage) {
        const std::vector<VectorSource> s = read_sources(sources);
        VectorOptions o = vector_options(algorithm, rule);
        PythonSignals signals;
        o.interrupter = &signals;
        VectorTexture t;
        {
          py::gil_scoped_release release;
          t = generate_vectors(volume, s, parse_vector_storage(storage), o);
        }
        return decoded(t);
      },
      py::arg("volume"), py::arg("sources"), py::arg("algorithm") = "splat",
      py::arg("rule") = "strongest", py::arg("storage") = "rgba32f",
      "One generation: float32 a[i, j, k, 4] (direction x, y, z in world space, strength), "
      "decoded from the storage. algorithm 'splat', 'brute', 'jfa', 'jfa+1' or 'jfa+2'; rule "
      "'strongest' or 'nearest'; storage 'rgba8', 'rgba16f' or 'rgba32f'");

  m.def(
      "exact",
      [](const Rows& points, const Rows& sources, const std::string& rule) {
        if (points.ndim() != 2 || points.shape(1) != 3)
          throw InvalidArgument("points must be an array of shape (N, 3)");
        const std::vector<VectorSource> s = read_sources(sources);
        const VectorRule r = parse_vector_rule(rule);
        py::array_t<double> values({points.shape(0), py::ssize_t{4}});
        py::array_t<std::int32_t> winners(points.shape(0));
        for (py::ssize_t i = 0; i < points.shape(0); ++i) {
          const VectorValue v =
              vector_at({points.at(i, 0), points.at(i, 1), points.at(i, 2)}, s, r);
          values.mutable_at(i, 0) = v.direction.x, values.mutable_at(i, 1) = v.direction.y;
          values.mutable_at(i, 2) = v.direction.z, values.mutable_at(i, 3) = v.strength;
          winners.mutable_at(i) = v.source;
        }
        return py::make_tuple(values, winners);
      },
      py::arg("points"), py::arg("sources"), py::arg("rule") = "strongest",
      "The definition at world points, in double precision: (float64 (N, 4) direction and "
      "strength, int32 (N,) the winning source or -1)");

  py::class_<PySimulation>(m, "Simulation",
                           "A field that moves with its sources: each step generates, decays "
                           "and blends")
      .def(py::init([](const VectorVolume& volume, const std::string& storage,
                       const std::string& algorithm, const std::string& rule, double decay_per_s) {
             return std::make_unique<PySimulation>(volume, parse_vector_storage(storage),
                                                   vector_options(algorithm, rule), decay_per_s);
           }),
           py::arg("volume"), py::arg("storage") = "rgba8", py::arg("algorithm") = "splat",
           py::arg("rule") = "strongest", py::arg("decay_per_s") = 1.0)
      .def(
          "step",
          [](PySimulation& sim, const Rows& sources, double dt_s) {
            const std::vector<VectorSource> s = read_sources(sources);
            py::gil_scoped_release release;
            std::unique_lock write(sim.lock);
            sim.sim.step(s, dt_s);
          },
          py::arg("sources"), py::arg("dt"),
          "One fixed step of dt seconds; if it raises, the field is unchanged")
      .def(
          "field",
          [](const PySimulation& sim) { return decoded(copy_of(sim, &VectorSimulation::field)); },
          "The blended field, float32 a[i, j, k, 4]: what shaders sample")
      .def(
          "current",
          [](const PySimulation& sim) { return decoded(copy_of(sim, &VectorSimulation::current)); },
          "The last step's generation, float32 a[i, j, k, 4]")
      .def(
          "sample",
          [](const PySimulation& sim, const Rows& points) {
            return sample_points(sim.sim.volume(), copy_of(sim, &VectorSimulation::field), points);
          },
          py::arg("points"),
          "Trilinear samples of the field at world points (N, 3): float64 (N, 4) rows (vector "
          "x, y, z — direction times strength — and strength); zero outside the box")
      .def(
          "render",
          [](const PySimulation& sim, int width, int height, std::optional<std::vector<double>> eye,
             bool sheet) {
            VectorViewOptions o;
            o.width = width;
            o.height = height;
            if (eye) {
              o.auto_eye = false;
              o.eye = vec3_arg(*eye, "eye");
            }
            o.sheet = sheet;
            Image img;
            {
              py::gil_scoped_release release;
              std::shared_lock read(sim.lock);
              img = render_vectors(sim.sim.volume(), sim.sim.field(), o);
            }
            py::array_t<std::uint8_t> out(
                {py::ssize_t{height}, py::ssize_t{width}, py::ssize_t{3}});
            std::copy(img.rgb.begin(), img.rgb.end(), out.mutable_data());
            return out;
          },
          py::arg("width") = 640, py::arg("height") = 480, py::arg("eye") = py::none(),
          py::arg("sheet") = false,
          "The visualiser's picture of the field as uint8 (height, width, 3), with the reactive "
          "sheet when asked")
      .def_property_readonly("steps",
                             [](const PySimulation& sim) {
                               py::gil_scoped_release release;
                               std::shared_lock read(sim.lock);
                               return sim.sim.steps();
                             })
      .def_property_readonly("last_times", [](const PySimulation& sim) {
        VectorPassTimes t;
        {
          py::gil_scoped_release release;
          std::shared_lock read(sim.lock);
          t = sim.sim.last_times();
        }
        py::dict d;
        d["search_ms"] = t.search_ms, d["seed_ms"] = t.seed_ms, d["flood_ms"] = t.flood_ms;
        d["blend_ms"] = t.blend_ms, d["total_ms"] = t.total_ms();
        return d;
      });
}

}  // namespace voxfield::python
