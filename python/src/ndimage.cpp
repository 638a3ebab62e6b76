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

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
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

// The chunks of a grid (of edge `edge`) that cover `box`, which starts at the origin.
std::vector<Vec3i> chunks_covering(const Box3i& box, int edge) {
  std::vector<Vec3i> coords;
  for (int z = 0; z * edge < box.end.z; ++z)
    for (int y = 0; y * edge < box.end.y; ++y)
      for (int x = 0; x * edge < box.end.x; ++x) coords.push_back({x, y, z});
  return coords;
}

// One row of the input to occupancy: 1 where the element is zero (a site). Called with a constant
// `stride` for contiguous rows, so the loop vectorises there.
template <class T>
inline void mark_zeros(const char* src, py::ssize_t stride, int run, std::uint8_t* dst) {
  for (int x = 0; x < run; ++x) {
    T v;
    std::memcpy(&v, src + x * stride, sizeof v);
    dst[x] = v == T(0);
  }
}

// Reads the input into `occupancy` (bounded by `box`) chunk by chunk in parallel, straight from
// NumPy's memory in any order and strides: no dense copy of it (at 256^3 the serial copy and its
// conversion into chunks took longer than the Manhattan transform itself).
template <class T>
void read_sites(const Strided& in, const Box3i& box, Grid<std::uint8_t>& occupancy) {
  const int edge = occupancy.chunk_edge();
  const std::int64_t volume = occupancy.chunk_volume();
  occupancy.generate_chunks(chunks_covering(box, edge), [&](Vec3i coord, std::uint8_t* voxels) {
    const Box3i cb = occupancy.chunk_box(coord);
    const Box3i part = cb.intersect(box);
    if (part != cb) std::fill(voxels, voxels + volume, std::uint8_t{0});  // beyond: no site
    const int run = part.end.x - part.begin.x;
    for (int z = part.begin.z; z < part.end.z; ++z)
      for (int y = part.begin.y; y < part.end.y; ++y) {
        // NumPy's axes 0, 1, 2 are voxfield's z, y, x.
        const char* src =
            in.data + z * in.strides[0] + y * in.strides[1] + part.begin.x * in.strides[2];
        std::uint8_t* dst = voxels + ((z - cb.begin.z) * edge + (y - cb.begin.y)) * edge +
                            (part.begin.x - cb.begin.x);
        if (in.strides[2] == static_cast<py::ssize_t>(sizeof(T)))
          mark_zeros<T>(src, sizeof(T), run, dst);
        else
          mark_zeros<T>(src, in.strides[2], run, dst);
      }
  });
}

// The reader of the input's dtype (chosen while the GIL is held), or null for dtypes the Python
// side converts first with input != 0.
using SiteReader = void (*)(const Strided&, const Box3i&, Grid<std::uint8_t>&);
SiteReader reader_for(const py::array& input) {
  const char kind = input.dtype().kind();
  const py::ssize_t size = input.dtype().itemsize();
  if (kind == 'b') return &read_sites<std::uint8_t>;
  if (kind == 'i' || kind == 'u') {
    switch (size) {
      case 1:
        return &read_sites<std::uint8_t>;
      case 2:
        return &read_sites<std::uint16_t>;
      case 4:
        return &read_sites<std::uint32_t>;
      case 8:
        return &read_sites<std::uint64_t>;
    }
  }
  if (kind == 'f' && size == 4) return &read_sites<float>;
  if (kind == 'f' && size == 8) return &read_sites<double>;
  return nullptr;
}

// Calls row(y, z, x_begin, x_end, values) for every row of `box` (which starts at the origin) in
// `grid`, chunk by chunk in parallel; `values` points at the row's stored values from x_begin on,
// or is null when the chunk is uniform (its value is then grid.chunk_view(...).uniform_value,
// passed as `uniform`). The field's own chunks are read in place, never copied densely.
template <class T, class F>
void for_each_row(const Grid<T>& grid, const Box3i& box, F&& row) {
  const int edge = grid.chunk_edge();
  const std::vector<Vec3i> coords = chunks_covering(box, edge);
  parallel_for(coords.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) {
      const ChunkView<T> view = grid.chunk_view(coords[c]);
      const Box3i cb = view.box.intersect(box);
      for (int z = cb.begin.z; z < cb.end.z; ++z)
        for (int y = cb.begin.y; y < cb.end.y; ++y) {
          const T* values =
              view.uniform() ? nullptr
                             : view.voxels + (cb.begin.x - view.box.begin.x) +
                                   edge * ((y - view.box.begin.y) + edge * (z - view.box.begin.z));
          row(y, z, cb.begin.x, cb.end.x, values, view.uniform_value);
        }
    }
  });
}

// Writes out[x] = value(x) for x in [x0, x1) of one output row (`stride` bytes apart; constant
// for contiguous outputs, so the loop vectorises there). `value` is copied into a local first, and
// the lambdas passed here capture their constants by value: the output is written through char*,
// which may alias anything whose address escaped, so constants reached through a reference would
// be reloaded for every element and keep the loop scalar.
template <class Out, class F>
inline void write_row(char* row, py::ssize_t stride, int x0, int x1, const F& value_ref) {
  const F value = value_ref;
  if (stride == static_cast<py::ssize_t>(sizeof(Out))) {
    for (int x = x0; x < x1; ++x) {
      const Out v = value(x);
      std::memcpy(row + x * static_cast<py::ssize_t>(sizeof(Out)), &v, sizeof v);
    }
  } else {
    for (int x = x0; x < x1; ++x) {
      const Out v = value(x);
      std::memcpy(row + x * stride, &v, sizeof v);
    }
  }
}

// The int32 distances of an integer metric (taxicab, chessboard) from the field's values (see
// distance_transform).
template <class T>
void write_from_values(const Grid<T>& values, const DistanceEncoding& encoding, const Box3i& box,
                       double max_distance, const Strided& dist) {
  const double clamp = max_distance > 0 ? max_distance : INFINITY;
  // Integer storage saturates at its range: a stored extreme is "beyond", as +inf in f32.
  const double saturated =
      std::is_integral_v<T> ? encoding.decode(std::numeric_limits<T>::max()) : INFINITY;
  // f32 storage holds the distance itself (scale 1, bias 0): no per-element division.
  const bool identity = encoding.scale == 1 && encoding.bias == 0;
  const auto magnitude = [saturated, identity, encoding](T stored, double& sign) {
    const double v = std::is_floating_point_v<T> && identity
                         ? static_cast<double>(stored)
                         : encoding.decode(static_cast<double>(stored));
    sign = v < 0 ? -1.0 : 1.0;
    const double a = std::abs(v);
    return a >= saturated ? INFINITY : a;
  };
  const auto integer = [magnitude, clamp](T stored) {
    double sign;
    const double a = magnitude(stored, sign);
    // No zero element anywhere: -1 (SciPy leaves -1 there too).
    return std::isfinite(a) ? static_cast<std::int32_t>(sign * std::min(a, clamp))
                            : std::int32_t{-1};
  };
  // Integer storage: every stored value's output, decoded once (at most 2^16 of them) and looked
  // up per element, where the volume has more elements than the table.
  std::vector<std::int32_t> table;
  if constexpr (std::is_integral_v<T>) {
    if (box.volume() > std::int64_t{std::numeric_limits<T>::max()} + 1) {
      table.resize(std::size_t{std::numeric_limits<T>::max()} + 1);
      for (std::size_t v = 0; v < table.size(); ++v) table[v] = integer(static_cast<T>(v));
    }
  }
  for_each_row(values, box, [&](int y, int z, int x0, int x1, const T* row, T uniform) {
    char* out = dist.data + z * dist.strides[0] + y * dist.strides[1];
    if (!table.empty() && row) {
      const std::int32_t* t = table.data();
      write_row<std::int32_t>(out, dist.strides[2], x0, x1, [t, row, x0](int x) {
        return t[static_cast<std::size_t>(row[x - x0])];
      });
    } else if (!row) {
      const std::int32_t d = integer(uniform);
      write_row<std::int32_t>(out, dist.strides[2], x0, x1, [d](int) { return d; });
    } else {
      write_row<std::int32_t>(out, dist.strides[2], x0, x1,
                              [integer, row, x0](int x) { return integer(row[x - x0]); });
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
  const Box3i box =
      Box3i::from_size({static_cast<int>(n[2]), static_cast<int>(n[1]), static_cast<int>(n[0])});
  // The peak beside the outputs, per element of the chunks covering the volume (whole 32^3 chunks:
  // a thin volume is stored in far more elements than it has): the input's zeros as a grid (1
  // byte), the field (4 bytes) and its nearest sites when computed (6 bytes).
  const auto chunks_along = [](py::ssize_t e) { return static_cast<std::size_t>((e + 31) / 32); };
  const std::size_t stored =
      mul_sat(mul_sat(chunks_along(n[0]) * chunks_along(n[1]), chunks_along(n[2])), 32 * 32 * 32);
  require_memory(mul_sat(stored, 1 + 4 + (indices || metric == Metric::kEuclidean ? 6 : 0)), 0,
                 "voxfield.ndimage", "a transform of " + std::to_string(count) + " elements");
  const SiteReader read = reader_for(input);
  if (!read) throw InvalidArgument("voxfield.ndimage: unsupported dtype");
  // Every array's address and strides are read while the GIL is held; the caller holds the arrays,
  // so their memory outlives the call.
  const Strided in = strided(input);
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

  py::gil_scoped_release release;
  std::optional<ThreadLimit> limit;
  if (threads > 0) limit.emplace(threads);
  Grid<std::uint8_t> occupancy(32, 0, box);
  read(in, box, occupancy);

  DistanceOptions o;
  o.metric = metric;
  o.signed_distance = signed_distance;
  o.max_distance = max_distance;
  o.domain = box;
  if (metric == Metric::kEuclidean) o.spacing = spacing;
  // Unit-sampled Euclidean distances without indices go straight into the float64 output
  // (compute_distance_field_into): the exact squared distance is an integer, and its float64
  // square root is SciPy's value bit for bit. Integer metrics are exact in a field's storage and
  // are read from its values. Everything else (anisotropic sampling, indices) needs the nearest
  // sites: SciPy sums each axis' squared offset in its own order, and the sites give the offsets.
  const bool unit = spacing == std::array<double, 3>{1, 1, 1};
  const bool aligned = reinterpret_cast<std::uintptr_t>(dist.data) % alignof(double) == 0 &&
                       std::all_of(dist.strides.begin(), dist.strides.end(), [](py::ssize_t b) {
                         return b % static_cast<py::ssize_t>(sizeof(double)) == 0;
                       });
  const bool dense = !indices && metric == Metric::kEuclidean && unit && aligned;
  const bool from_values = !indices && metric != Metric::kEuclidean;
  o.nearest_sites = !dense && !from_values;
  // Integer metrics in 16 bits where every distance fits (half the field's memory and traffic).
  const double largest_l1 = static_cast<double>(n[0] + n[1] + n[2] - 3);
  o.storage = from_values && largest_l1 < 32767 ? Storage::kU16 : Storage::kF32;
  PythonSignals signals;
  o.interrupter = &signals;
  if (dense) {
    // voxfield.ndimage passes aligned, native float64 outputs only (a copy otherwise); a caller
    // of this private function that does not take the sites' path. NumPy's axes 0, 1, 2 are
    // voxfield's z, y, x.
    constexpr py::ssize_t kSize = sizeof(double);
    const DenseDistances<double> out{
        reinterpret_cast<double*>(dist.data),
        {dist.strides[2] / kSize, dist.strides[1] / kSize, dist.strides[0] / kSize}};
    compute_distance_field_into(occupancy, o, out);
    return;
  }
  const DistanceField field = compute_distance_field(occupancy, o);
  if (from_values) {
    std::visit(
        [&](const auto& grid) { write_from_values(grid, field.encoding, box, max_distance, dist); },
        field.values);
    return;
  }
  // The outputs are written chunk by chunk from the field's own site grid (no dense copy of it:
  // at 256^3 that copy was 100 MB of fresh pages).
  const Grid<SiteOffset>& sites = *field.sites;
  const std::array<double, 3> s{spacing[2], spacing[1], spacing[0]};  // NumPy axes 0, 1, 2
  const double clamp = max_distance > 0 ? max_distance : INFINITY;
  const int edge = occupancy.chunk_edge();  // the field's grids share the world's chunks
  for_each_row(
      sites, box, [&](int y, int z, int x0, int x1, const SiteOffset* row, SiteOffset uniform) {
        const auto offset_at = [&](int x) { return row ? row[x - x0] : uniform; };
        // The element's own occupancy (a zero element is a site: negative when signed).
        const ChunkView<std::uint8_t> occ = occupancy.chunk_view(occupancy.chunk_of({x0, y, z}));
        const std::uint8_t* occ_row =
            occ.uniform() ? nullptr
                          : occ.voxels + (x0 - occ.box.begin.x) +
                                edge * ((y - occ.box.begin.y) + edge * (z - occ.box.begin.z));
        const auto sign_at = [&](int x) {
          const bool site = occ_row ? occ_row[x - x0] != 0 : occ.uniform_value != 0;
          return signed_distance && site ? -1.0 : 1.0;
        };
        // NumPy's axes 0, 1, 2 are voxfield's z, y, x.
        if (distances) {
          char* out = dist.data + z * dist.strides[0] + y * dist.strides[1];
          if (metric == Metric::kEuclidean) {
            write_row<double>(out, dist.strides[2], x0, x1, [&](int x) {
              const SiteOffset o = offset_at(x);
              double d = clamp;
              if (!o.none()) {
                // SciPy's order: each axis' offset times its sampling, squared, summed from axis 0.
                const double t0 = o.dz * s[0], t1 = o.dy * s[1], t2 = o.dx * s[2];
                d = std::min(std::sqrt(t0 * t0 + t1 * t1 + t2 * t2), clamp);
              }
              return d * sign_at(x);
            });
          } else {
            write_row<std::int32_t>(out, dist.strides[2], x0, x1, [&](int x) {
              const SiteOffset o = offset_at(x);
              std::int32_t d = -1;  // no zero element anywhere (SciPy leaves -1 there too)
              if (!o.none()) {
                const int u = std::abs(o.dz), v = std::abs(o.dy), w = std::abs(o.dx);
                const int m = metric == Metric::kManhattan ? u + v + w : std::max({u, v, w});
                d = static_cast<std::int32_t>(std::min<double>(m, clamp));
              } else if (max_distance > 0) {
                d = static_cast<std::int32_t>(max_distance);
              }
              return static_cast<std::int32_t>(sign_at(x) * d);
            });
          }
        }
        if (indices) {
          // indices[k] holds the coordinate along the input's axis k (padded axis 3 - nd + k).
          for (int k = 0; k < nd; ++k) {
            const int axis = 3 - nd + k;
            char* out = idx.data + k * idx_axis_stride + z * idx.strides[0] + y * idx.strides[1];
            write_row<std::int32_t>(out, idx.strides[2], x0, x1, [&](int x) {
              const SiteOffset o = offset_at(x);
              if (o.none()) return std::int32_t{-1};
              return static_cast<std::int32_t>(axis == 0   ? z + o.dz
                                               : axis == 1 ? y + o.dy
                                                           : x + o.dx);
            });
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
