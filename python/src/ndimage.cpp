// voxfield.ndimage's engine: the exact transforms of voxfield behind SciPy's distance_transform_edt
// and distance_transform_cdt (python/voxfield/ndimage.py checks the arguments and shapes the
// results as SciPy does; this file reads any NumPy array, computes, and writes the outputs).
//
// Axes: NumPy's last axis is voxfield's x (fastest), so a C-ordered array is read in its own order;
// arrays of fewer than three dimensions get leading axes of length 1. SciPy measures "the distance
// of every non-zero element to the nearest zero element": the zero elements are voxfield's sites
// (its solid voxels). Distances are computed from the nearest site in float64, summing the axes'
// squares in SciPy's order, so they equal SciPy's where the nearest zero is at the same distance.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>
#include <variant>
#include <vector>

#include "signals.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/interrupt.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace py = pybind11;

namespace voxfield::python {
namespace {

struct Strided {
  char* data;
  std::array<py::ssize_t, 3> strides{0, 0, 0};  // bytes, for the padded axes 0, 1, 2
};

// Shape and strides of an array padded to three axes (leading axes of length 1).
std::array<py::ssize_t, 3> padded_shape(const py::array& a) {
  std::array<py::ssize_t, 3> s{1, 1, 1};
  const int nd = static_cast<int>(a.ndim());
  for (int i = 0; i < nd; ++i) s[3 - nd + i] = a.shape(i);
  return s;
}
Strided strided(const py::array& a) {
  Strided s{static_cast<char*>(const_cast<void*>(a.data()))};
  const int nd = static_cast<int>(a.ndim());
  for (int i = 0; i < nd; ++i) s.strides[3 - nd + i] = a.strides(i);
  return s;
}

// The occupancy voxfield sees: 1 where the input element is zero (a site), x fastest.
template <class T>
void read_zeros(const Strided& in, std::array<py::ssize_t, 3> n, std::vector<std::uint8_t>& out) {
  std::size_t i = 0;
  for (py::ssize_t a0 = 0; a0 < n[0]; ++a0)
    for (py::ssize_t a1 = 0; a1 < n[1]; ++a1) {
      const char* row = in.data + a0 * in.strides[0] + a1 * in.strides[1];
      for (py::ssize_t a2 = 0; a2 < n[2]; ++a2, ++i) {
        T v;
        std::memcpy(&v, row + a2 * in.strides[2], sizeof v);
        out[i] = v == T(0);
      }
    }
}

bool read_input(const py::array& input, std::array<py::ssize_t, 3> n,
                std::vector<std::uint8_t>& out) {
  const Strided s = strided(input);
  const char kind = input.dtype().kind();
  const py::ssize_t size = input.dtype().itemsize();
  if (kind == 'b') return read_zeros<std::uint8_t>(s, n, out), true;
  if (kind == 'i' || kind == 'u') {
    switch (size) {
      case 1:
        return read_zeros<std::uint8_t>(s, n, out), true;
      case 2:
        return read_zeros<std::uint16_t>(s, n, out), true;
      case 4:
        return read_zeros<std::uint32_t>(s, n, out), true;
      case 8:
        return read_zeros<std::uint64_t>(s, n, out), true;
    }
  }
  if (kind == 'f' && size == 4) return read_zeros<float>(s, n, out), true;
  if (kind == 'f' && size == 8) return read_zeros<double>(s, n, out), true;
  return false;  // the Python side converts other dtypes with input != 0
}

// Calls f(x, y, z, value) for every voxel of `box` (which starts at the origin) in `grid`, chunk
// by chunk in parallel: the field's own chunks are read in place, never copied densely.
template <class T, class F>
void for_each_voxel(const Grid<T>& grid, const Box3i& box, F&& f) {
  const int edge = grid.chunk_edge();
  const Vec3i chunks{(box.end.x + edge - 1) / edge, (box.end.y + edge - 1) / edge,
                     (box.end.z + edge - 1) / edge};
  const std::size_t chunk_count = static_cast<std::size_t>(chunks.x) * chunks.y * chunks.z;
  parallel_for(chunk_count, 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) {
      const Vec3i coord{static_cast<int>(c % chunks.x), static_cast<int>(c / chunks.x % chunks.y),
                        static_cast<int>(c / chunks.x / chunks.y)};
      const ChunkView<T> view = grid.chunk_view(coord);
      const Box3i cb = view.box.intersect(box);
      for (int z = cb.begin.z; z < cb.end.z; ++z)
        for (int y = cb.begin.y; y < cb.end.y; ++y)
          for (int x = cb.begin.x; x < cb.end.x; ++x)
            f(x, y, z,
              view.uniform()
                  ? view.uniform_value
                  : view.voxels[(x - view.box.begin.x) +
                                edge * ((y - view.box.begin.y) + edge * (z - view.box.begin.z))]);
    }
  });
}

// The distances from the field's values (see distance_transform).
template <class T>
void write_from_values(const Grid<T>& values, const DistanceEncoding& encoding, const Box3i& box,
                       Metric metric, double max_distance, py::array& distances) {
  Strided dist = strided(distances);
  dist.data = static_cast<char*>(distances.mutable_data());
  const double clamp = max_distance > 0 ? max_distance : INFINITY;
  const double clamp_f32 = static_cast<double>(static_cast<float>(clamp));
  // Integer storage saturates at its range: a stored extreme is "beyond", as +inf in f32.
  const double saturated =
      std::is_integral_v<T> ? encoding.decode(std::numeric_limits<T>::max()) : INFINITY;
  for_each_voxel(values, box, [&](int x, int y, int z, T stored) {
    const double v = encoding.decode(static_cast<double>(stored));
    const double sign = v < 0 ? -1.0 : 1.0;
    double a = std::abs(v);
    if (a >= saturated) a = INFINITY;
    char* p = dist.data + z * dist.strides[0] + y * dist.strides[1] + x * dist.strides[2];
    if (metric == Metric::kEuclidean) {
      double d = clamp;
      // A clamped element reads float(D), which may round below D: anything at or above
      // float(D) is the clamp (a true distance that close to D differs from it by < 1 float ulp).
      if (a < clamp_f32) d = std::min(std::sqrt(std::nearbyint(a * a)), clamp);
      d *= sign;
      std::memcpy(p, &d, 8);
    } else {
      std::int32_t d = -1;  // no zero element anywhere (SciPy leaves -1 there too)
      if (std::isfinite(a)) d = static_cast<std::int32_t>(sign * std::min(a, clamp));
      std::memcpy(p, &d, 4);
    }
  });
}

// Computes the transform of `input` and writes the distances (float64 for euclidean, int32 for
// taxicab / chessboard) and the indices (int32, shape (ndim,) + input.shape) into the given arrays.
void distance_transform(const py::array& input, const std::string& metric_name,
                        std::optional<std::vector<double>> sampling, bool signed_distance,
                        double max_distance, int threads, std::optional<py::array> distances,
                        std::optional<py::array> indices) {
  const std::array<py::ssize_t, 3> n = padded_shape(input);
  const int nd = static_cast<int>(input.ndim());
  if (nd < 1 || nd > 3)
    throw InvalidArgument("voxfield.ndimage: inputs of 1 to 3 dimensions (got " +
                          std::to_string(nd) + ")");
  for (py::ssize_t e : n)
    if (e >= (py::ssize_t{1} << 29))
      throw InvalidArgument("voxfield.ndimage: an axis of 2^29 elements or more");
  const std::size_t count = static_cast<std::size_t>(n[0] * n[1] * n[2]);
  const Metric metric = metric_name == "euclidean" ? Metric::kEuclidean
                        : metric_name == "taxicab" ? Metric::kManhattan
                        : metric_name == "chessboard"
                            ? Metric::kChebyshev
                            : throw InvalidArgument("unknown metric " + metric_name);
  // Spacing per voxfield axis x, y, z = NumPy axes 2, 1, 0 (padded).
  std::array<double, 3> spacing{1, 1, 1};
  if (sampling) {
    for (int i = 0; i < nd; ++i) spacing[nd - 1 - i] = (*sampling)[static_cast<std::size_t>(i)];
  }
  if (count == 0) return;  // an empty array: empty outputs, as SciPy's
  if (!distances && !indices)
    throw InvalidArgument("voxfield.ndimage: neither distances nor indices asked for");
  // The peak beside the outputs: the input's zeros and their grid (1 byte each), the field
  // (4 bytes) and its nearest sites when computed (6 bytes).
  require_memory(mul_sat(count, 1 + 1 + 4 + (indices || metric == Metric::kEuclidean ? 6 : 0)), 0,
                 "voxfield.ndimage", "a transform of " + std::to_string(count) + " elements");
  std::vector<std::uint8_t> zeros(count);
  if (!read_input(input, n, zeros)) throw InvalidArgument("voxfield.ndimage: unsupported dtype");

  py::gil_scoped_release release;
  std::optional<ThreadLimit> limit;
  if (threads > 0) limit.emplace(threads);
  const Box3i box =
      Box3i::from_size({static_cast<int>(n[2]), static_cast<int>(n[1]), static_cast<int>(n[0])});
  Grid<std::uint8_t> occupancy(32, 0, box);
  occupancy.copy_from_dense(box, zeros.data());

  DistanceOptions o;
  o.metric = metric;
  o.signed_distance = signed_distance;
  o.max_distance = max_distance;
  o.domain = box;
  if (metric == Metric::kEuclidean) o.spacing = spacing;
  // Without indices the sites are needed only for anisotropic Euclidean distances: an isotropic
  // field's f32 value v is sqrt(d^2) rounded to float, and round(v^2) recovers the integer d^2
  // exactly while d^2 < 2^22, so float64 sqrt(d^2) is SciPy's value bit for bit. Integer metrics
  // are exact in f32. The site transform costs more, and its grid 6 bytes per element.
  const bool unit = spacing == std::array<double, 3>{1, 1, 1};
  const double largest_d2 = static_cast<double>(n[0] - 1) * (n[0] - 1) +
                            static_cast<double>(n[1] - 1) * (n[1] - 1) +
                            static_cast<double>(n[2] - 1) * (n[2] - 1);
  const bool from_values =
      !indices && (metric != Metric::kEuclidean || (unit && largest_d2 < double(1 << 22)));
  o.nearest_sites = !from_values;
  // Integer metrics in 16 bits where every distance fits (half the field's memory and traffic).
  const double largest_l1 = static_cast<double>(n[0] + n[1] + n[2] - 3);
  o.storage = from_values && metric != Metric::kEuclidean && largest_l1 < 32767 ? Storage::kU16
                                                                                : Storage::kF32;
  PythonSignals signals;
  o.interrupter = &signals;
  const DistanceField field = compute_distance_field(occupancy, o);
  if (from_values) {
    std::visit(
        [&](const auto& grid) {
          write_from_values(grid, field.encoding, box, metric, max_distance, *distances);
        },
        field.values);
    return;
  }
  // The outputs are written chunk by chunk from the field's own site grid (no dense copy of it:
  // at 256^3 that copy was 100 MB of fresh pages).
  const Grid<SiteOffset>& sites = *field.sites;
  const std::array<double, 3> s{spacing[2], spacing[1], spacing[0]};  // NumPy axes 0, 1, 2
  Strided dist{nullptr};
  if (distances) {
    dist = strided(*distances);
    dist.data = static_cast<char*>(distances->mutable_data());
  }
  Strided idx{nullptr};
  py::ssize_t idx_axis_stride = 0;
  if (indices) {
    // indices has shape (ndim,) + shape: its first axis selects the coordinate.
    idx.data = static_cast<char*>(indices->mutable_data());
    idx_axis_stride = indices->strides(0);
    for (int i = 0; i < nd; ++i) idx.strides[3 - nd + i] = indices->strides(i + 1);
  }
  const double clamp = max_distance > 0 ? max_distance : INFINITY;
  for_each_voxel(sites, box, [&](int x, int y, int z, const SiteOffset o) {
    // NumPy's axes 0, 1, 2 are voxfield's z, y, x.
    const py::ssize_t a0 = z, a1 = y, a2 = x;
    const std::size_t i = static_cast<std::size_t>((a0 * n[1] + a1) * n[2] + a2);
    const bool site = zeros[i] != 0;
    const double sign = signed_distance && site ? -1.0 : 1.0;
    const std::array<py::ssize_t, 3> off{o.none() ? 0 : o.dz, o.none() ? 0 : o.dy,
                                         o.none() ? 0 : o.dx};
    if (distances) {
      char* p = dist.data + a0 * dist.strides[0] + a1 * dist.strides[1] + a2 * dist.strides[2];
      if (metric == Metric::kEuclidean) {
        double d = clamp;
        if (!o.none()) {
          // SciPy's order: each axis' offset times its sampling, squared, summed from axis 0.
          const double t0 = off[0] * s[0], t1 = off[1] * s[1], t2 = off[2] * s[2];
          d = std::min(std::sqrt(t0 * t0 + t1 * t1 + t2 * t2), clamp);
        }
        d *= sign;
        std::memcpy(p, &d, 8);
      } else {
        std::int32_t d = -1;  // no zero element anywhere (SciPy leaves -1 there too)
        if (!o.none()) {
          const std::int64_t u = std::abs(off[0]), v = std::abs(off[1]), w = std::abs(off[2]);
          const std::int64_t m = metric == Metric::kManhattan ? u + v + w : std::max({u, v, w});
          d = static_cast<std::int32_t>(std::min<double>(static_cast<double>(m), clamp));
        } else if (max_distance > 0) {
          d = static_cast<std::int32_t>(max_distance);
        }
        d = static_cast<std::int32_t>(sign * d);
        std::memcpy(p, &d, 4);
      }
    }
    if (indices) {
      const std::array<py::ssize_t, 3> at{a0, a1, a2};
      char* base = idx.data + a0 * idx.strides[0] + a1 * idx.strides[1] + a2 * idx.strides[2];
      for (int k = 0; k < nd; ++k) {
        const int axis = 3 - nd + k;
        const std::int32_t v = o.none() ? -1 : static_cast<std::int32_t>(at[axis] + off[axis]);
        std::memcpy(base + k * idx_axis_stride, &v, 4);
      }
    }
  });
}

}  // namespace

void bind_ndimage(py::module_& m) {
  m.def("_distance_transform", &distance_transform, py::arg("input"), py::arg("metric"),
        py::arg("sampling"), py::arg("signed"), py::arg("max_distance"), py::arg("threads"),
        py::arg("distances"), py::arg("indices"),
        "The engine of voxfield.ndimage (use that module): writes distances and indices in place.");
}

}  // namespace voxfield::python
