// voxfield — marching cubes of a whole dense lattice in Flying Edges' passes.
//
// W. Schroeder, R. Maynard & B. Geveci, "Flying Edges: A High-Performance Scalable Isocontouring
// Algorithm", IEEE LDAV 2015: instead of visiting cells and looking their vertices up, classify
// every lattice edge first, count each row's crossings and triangles, turn the counts into
// offsets by a prefix sum, then write every vertex and every triangle exactly once at its final
// place — rows in parallel, no locks, no hash, no copy. Vertex numbers follow from the counts: a
// crossing's number is its row's first vertex plus the crossings before it on that row, which a
// population count of the row's crossing bits gives directly.
//
// Rows here are bit rows: pass 1 turns each sample row into bits (inside or not, 64 samples a
// word, checking for NaN on the way); an edge crosses where the bits of its two ends differ, so a
// row's x-, y- and z-edge crossings are XORs of whole words and a cell is active unless its eight
// corner bits agree. Pass 2 counts per row and per cell row (triangles by the case table of
// cube_cases.h, ambiguous faces by the asymptotic decider); pass 3 writes. The triangles, their
// positions, normals and sources are those of marching_cubes.cpp (same table, same arithmetic),
// only numbered by row instead of by chunk.
#include "flying_edges.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "bit_rows.h"
#include "cube_cases.h"
#include "mesh_memory.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield::detail::mesh {

bool flying_edges_applies(const Lattice& lattice, const MeshOptions& options) {
  return options.algorithm == Mesher::kMarchingCubes && lattice.values && !lattice.value &&
         !lattice.gradient && !lattice.color;
}

namespace {

// Triangles and centre vertices of each corner mask without an ambiguous face.
struct CaseCounts {
  std::array<std::uint8_t, 256> triangles{}, centres{};
  explicit CaseCounts(const CubeCases& table) {
    for (unsigned inside = 0; inside < 256; ++inside)
      if (!table.ambiguous_faces(inside)) {
        triangles[inside] = table.lookup(inside, 0).triangle_count;
        centres[inside] = table.lookup(inside, 0).centre_count;
      }
  }
};

// A cell row's eight crossing masks: the x-edges of the four sample rows (y, z), (y + 1, z),
// (y, z + 1), (y + 1, z + 1) (masks 0-3: edge j of the cube, cube_cases.h numbering), the y-edges
// of rows (y, z) and (y, z + 1) (masks 4, 5: edges 4-5 and 6-7, at x and x + 1), the z-edges of
// rows (y, z) and (y + 1, z) (masks 6, 7: edges 8-9 and 10-11, at x and x + 1).
//
// The numbers of all twelve edges' crossings in the cell at x, from the masks' numbers at x
// (RowRanks::ids_at): a y- or z-edge's crossing at x + 1 is numbered after the one at x when
// that one exists, which the cell's own crossed edges say. Edges the cell does not cross get a
// number too, which no triangle of the cell uses (only indices the next cells overwrite): all
// twelve without a branch per edge, which costs less than the mispredicted loop exits of visiting
// only the crossed ones (3-12 of them, varying cell to cell).
std::array<std::uint32_t, CubeCase::kCentre + 2> edge_ids(const std::array<std::uint64_t, 8>& at,
                                                          unsigned crossed) {
  std::array<std::uint32_t, CubeCase::kCentre + 2> ids{};
  for (std::size_t j = 0; j < 4; ++j) ids[j] = static_cast<std::uint32_t>(at[j]);
  for (std::size_t k = 0; k < 4; ++k) {
    const std::size_t edge = 4 + 2 * k;
    ids[edge] = static_cast<std::uint32_t>(at[4 + k]);
    ids[edge + 1] = static_cast<std::uint32_t>(at[4 + k] + (crossed >> edge & 1));
  }
  return ids;
}

// The samples with the inside convention folded in, as Block reads them (chunked_mesh.h): the
// same float arithmetic, so vertices come out bit for bit as the chunked driver's.
struct RowSamples {
  const Lattice& lattice;
  float iso;
  bool negate;
  std::ptrdiff_t sy, sz;
  int z_offset;  // FlyingEdges's: plane z here is plane z + z_offset of the lattice meshed
  // Per axis, the differences' spans (one and two spacings) and, where a span is a power of two
  // (unit spacings), its exact inverse: x * (1 / span) then rounds the same real number as
  // x / span, so the gradient is the same bit for bit for a multiplication's cost.
  std::array<std::array<double, 2>, 3> span{}, inverse{};
  std::array<bool, 3> exact_inverse{};
  RowSamples(const Lattice& l, int z_offset_planes)
      : lattice(l),
        iso(static_cast<float>(l.iso)),
        negate(l.sign < 0),
        sy(l.n.x),
        sz(static_cast<std::ptrdiff_t>(l.n.x) * l.n.y),
        z_offset(z_offset_planes) {
    for (std::size_t a = 0; a < 3; ++a) {
      int exponent = 0;
      const double mantissa = std::frexp(l.spacing[a], &exponent);
      exact_inverse[a] = mantissa == 0.5 && exponent > -1000 && exponent < 1000;
      for (std::size_t k = 0; k < 2; ++k) {
        span[a][k] = static_cast<double>(k + 1) * l.spacing[a];
        inverse[a][k] = 1 / span[a][k];
      }
    }
  }
  float s_of(float v) const { return negate ? iso - v : v - iso; }
  float s(std::ptrdiff_t i) const { return s_of(lattice.values[i]); }
  std::ptrdiff_t index(int x, int y, int z) const { return x + sy * y + sz * z; }
  // Central differences at a sample whose six neighbours all lie in the lattice: gradient()'s
  // arithmetic without its per-axis face tests.
  std::array<double, 3> inner_gradient(std::ptrdiff_t i) const {
    const std::ptrdiff_t step[3] = {1, sy, sz};
    std::array<double, 3> g;
    for (std::size_t a = 0; a < 3; ++a) {
      const double difference = static_cast<double>(s(i + step[a])) - s(i - step[a]);
      g[a] = exact_inverse[a] ? difference * inverse[a][1] : difference / span[a][1];
    }
    return g;
  }
  // Whether the edge from (x, y, z) along `axis` has both ends' six neighbours in the lattice.
  bool inner_edge(int x, int y, int z, int axis) const {
    const Vec3i n = lattice.n;
    return x >= 1 && y >= 1 && z >= 1 && x + 1 + (axis == 0) < n.x && y + 1 + (axis == 1) < n.y &&
           z + 1 + (axis == 2) < n.z;
  }
  // Central differences, one-sided on the lattice's faces (Block::gradient, the same rounding).
  std::array<double, 3> gradient(int x, int y, int z) const {
    const std::ptrdiff_t i = index(x, y, z);
    const int p[3] = {x, y, z};
    const std::ptrdiff_t step[3] = {1, sy, sz};
    std::array<double, 3> g;
    for (std::size_t a = 0; a < 3; ++a) {
      const bool down = p[a] > 0, up = p[a] < lattice.n[static_cast<int>(a)] - 1;
      const std::ptrdiff_t lo = down ? i - step[a] : i, hi = up ? i + step[a] : i;
      const std::size_t k = static_cast<std::size_t>(up) + static_cast<std::size_t>(down) - 1;
      const double difference = static_cast<double>(s(hi)) - s(lo);
      g[a] = exact_inverse[a] ? difference * inverse[a][k] : difference / span[a][k];
    }
    return g;
  }
};

struct Vertex {
  std::array<float, 3> position, normal;
  std::uint64_t source;
};

// A crossing before its normal is scaled to unit length.
struct UnscaledVertex {
  std::array<float, 3> position;
  std::array<double, 3> normal;
  std::uint64_t source;
};

// The crossing on the edge from lattice point (x, y, z) along `axis` (marching_cubes.cpp's
// vertex(), without an analytic value or gradient), its normal not yet scaled.
UnscaledVertex unscaled_edge_vertex(const RowSamples& in, int x, int y, int z, int axis) {
  const std::ptrdiff_t i0 = in.index(x, y, z);
  const std::ptrdiff_t i1 = i0 + (axis == 0 ? 1 : axis == 1 ? in.sy : in.sz);
  const double s0 = in.s(i0), s1 = in.s(i1);
  const double t = s0 / (s0 - s1);  // the signs differ, so s0 != s1
  // (The plane in the whole lattice's numbering before the fraction is added: a slab's vertex is
  // then the same double as the whole lattice's.)
  std::array<double, 3> at{static_cast<double>(x), static_cast<double>(y),
                           static_cast<double>(z + in.z_offset)};
  at[static_cast<std::size_t>(axis)] += t;
  const auto position = lattice_position(in.lattice, at);
  const int qx = x + (axis == 0), qy = y + (axis == 1), qz = z + (axis == 2);
  const bool inner = in.inner_edge(x, y, z, axis);
  const auto g0 = inner ? in.inner_gradient(i0) : in.gradient(x, y, z);
  const auto g1 = inner ? in.inner_gradient(i1) : in.gradient(qx, qy, qz);
  std::array<double, 3> normal{g0[0] + t * (g1[0] - g0[0]), g0[1] + t * (g1[1] - g0[1]),
                               g0[2] + t * (g1[2] - g0[2])};
  if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0)
    normal[static_cast<std::size_t>(axis)] = s0 < 0 ? 1 : -1;
  return {{static_cast<float>(position[0]), static_cast<float>(position[1]),
           static_cast<float>(position[2])},
          normal,
          static_cast<std::uint64_t>((s0 < 0 ? i0 : i1) + in.sz * in.z_offset)};
}

Vertex edge_vertex(const RowSamples& in, int x, int y, int z, int axis) {
  const UnscaledVertex v = unscaled_edge_vertex(in, x, y, z, axis);
  return {v.position, unit_normal(v.normal), v.source};
}

// edge_vertex() called out of line. (Inlined into centre_vertex(), GCC 12 at -O3 gave some means
// one unit in the last place away from the chunked driver's mean of the stored floats; the cause
// was not found — no fast-math, no contraction — and out of line the two agree. The random-lattice
// tests compare every centre vertex with the chunked driver's, so a recurrence fails them.)
[[gnu::noinline]] Vertex stored_edge_vertex(const RowSamples& in, int x, int y, int z, int axis) {
  return edge_vertex(in, x, y, z, axis);
}

// Centre vertex c of a cell's case (a loop fanned from its mean): the mean of the loop's
// crossings, recomputed here bit for bit as the rows owning them write them.
Vertex centre_vertex(const RowSamples& in, const CubeCase& cc, int c, int x, int y, int z) {
  const auto& edges = cube_edges();
  const int count = cc.centre_sizes[static_cast<std::size_t>(c)];
  std::array<double, 3> mean{0, 0, 0}, normal{0, 0, 0};
  std::uint64_t source = 0;
  for (int i = 0; i < count; ++i) {
    const CubeEdge& e =
        edges[cc.centre_edges[static_cast<std::size_t>(c)][static_cast<std::size_t>(i)]];
    const Vertex on = stored_edge_vertex(in, x + (e.from & 1), y + (e.from >> 1 & 1),
                                         z + (e.from >> 2 & 1), e.axis);
    if (i == 0) source = on.source;
    for (std::size_t a = 0; a < 3; ++a) {
      mean[a] += on.position[a] / static_cast<double>(count);
      normal[a] += on.normal[a];
    }
  }
  return {{static_cast<float>(mean[0]), static_cast<float>(mean[1]), static_cast<float>(mean[2])},
          unit_normal(normal),
          source};
}

}  // namespace

namespace {

// Calls f(x, inside) for every cell of cell row (rows b[0..3], see edge_ids) whose corners are
// not all on one side, x increasing; inside is its corner mask (bit c: corner c inside).
template <class F>
void for_each_active_cell(const std::uint64_t* const b[4], std::size_t words, int nx, F&& f) {
  const std::size_t last = static_cast<std::size_t>(nx - 2) >> 6;  // the word of the last cell
  for (std::size_t w = 0; w <= last; ++w) {
    const auto any = [&](std::size_t i) {
      return i < words ? b[0][i] | b[1][i] | b[2][i] | b[3][i] : 0;
    };
    const auto all = [&](std::size_t i) {
      return i < words ? b[0][i] & b[1][i] & b[2][i] & b[3][i] : 0;
    };
    const std::uint64_t a = any(w), a_next = a >> 1 | any(w + 1) << 63;
    const std::uint64_t e = all(w), e_next = e >> 1 | all(w + 1) << 63;
    std::uint64_t active = ~((e & e_next) | (~a & ~a_next));
    if (w == last) active &= low_bits(static_cast<unsigned>(nx - 2) & 63) << 1 | 1;
    while (active) {
      const int x = static_cast<int>(64 * w) + std::countr_zero(active);
      active &= active - 1;
      f(x, two_bits(b[0], x) | two_bits(b[1], x) << 2 | two_bits(b[2], x) << 4 |
               two_bits(b[3], x) << 6);
    }
  }
}

}  // namespace

FlyingEdges::FlyingEdges(const Lattice& lattice, Interrupter* interrupter, int z_offset)
    : lattice_(lattice),
      progress_(std::make_unique<Progress>(interrupter, "marching cubes",
                                           3 * static_cast<std::int64_t>(lattice.n.z))),
      z_offset_(z_offset) {
  const Vec3i n = lattice.n;
  const std::size_t rows = static_cast<std::size_t>(n.y) * static_cast<std::size_t>(n.z);
  require_memory(mul_sat(rows, 2 * 8 + 3 * 4), 0, "mesh", "marching cubes' row bookkeeping");
  // Pass 1: bit rows (and the refusal of a NaN or infinite sample).
  inside_ = std::make_unique<InsideBits>(lattice, *progress_, z_offset);
  words_ = inside_->words();
  Progress& progress = *progress_;
  // Pass 2: each row's counts, then their prefix sums.
  // Row r's counts go to entry r + 1 of first_vertex_ and first_index_, summed in place after.
  resize_on_huge_pages(x_count_, rows);
  resize_on_huge_pages(y_count_, rows);
  resize_on_huge_pages(z_count_, rows);
  count_rows(
      n.z, rows, progress, [this](int z) { count_plane(z); }, first_vertex_, first_index_);
  vertices_ = first_vertex_[rows];
  indices_ = first_index_[rows];
}

void FlyingEdges::count_plane(int z) {
  const Vec3i n = lattice_.n;
  const RowSamples in(lattice_, z_offset_);
  const CubeCases& table = CubeCases::get();
  static const CaseCounts counts(table);
  std::vector<std::uint64_t> scratch(words_);
  for (int y = 0; y < n.y; ++y) {
    const std::size_t r = static_cast<std::size_t>(y) + static_cast<std::size_t>(n.y) * z;
    if (inside_->quiet(y, z)) {  // its counts stay 0
      first_vertex_[r + 1] = first_index_[r + 1] = 0;
      continue;
    }
    const std::uint64_t* b = inside_->row(y, z);
    x_crossings(b, words_, n.x, scratch.data());
    x_count_[r] = static_cast<std::uint32_t>(population(scratch.data(), words_));
    if (y + 1 < n.y) {
      differences(b, inside_->row(y + 1, z), words_, scratch.data());
      y_count_[r] = static_cast<std::uint32_t>(population(scratch.data(), words_));
    }
    if (z + 1 < n.z) {
      differences(b, inside_->row(y, z + 1), words_, scratch.data());
      z_count_[r] = static_cast<std::uint32_t>(population(scratch.data(), words_));
    }
    std::uint64_t triangles = 0, centres = 0;
    if (y + 1 < n.y && z + 1 < n.z) {
      const std::uint64_t* rows[4] = {b, inside_->row(y + 1, z), inside_->row(y, z + 1),
                                      inside_->row(y + 1, z + 1)};
      const float* v0 = lattice_.values + in.index(0, y, z);
      for_each_active_cell(rows, words_, n.x, [&](int x, unsigned inside) {
        if (!table.ambiguous_faces(inside)) {  // most cells: a 512-byte table, not the cases
          triangles += counts.triangles[inside];
          centres += counts.centres[inside];
          return;
        }
        float v[8];
        for (int c = 0; c < 8; ++c)
          v[c] = in.s_of(v0[x + (c & 1) + in.sy * (c >> 1 & 1) + in.sz * (c >> 2 & 1)]);
        const CubeCase& cc = table.lookup(inside, table.joined_faces(v, inside));
        triangles += cc.triangle_count;
        centres += cc.centre_count;
      });
    }
    first_vertex_[r + 1] = std::uint64_t{x_count_[r]} + y_count_[r] + z_count_[r] + centres;
    first_index_[r + 1] = 3 * triangles;
  }
}

void FlyingEdges::write(const WeldOutput& out) const {
  write_planes(0, lattice_.n.z, lattice_.n.z, out);
}

std::uint64_t FlyingEdges::vertices_before(int z) const {
  return first_vertex_[static_cast<std::size_t>(lattice_.n.y) * static_cast<std::size_t>(z)];
}

std::uint64_t FlyingEdges::indices_before(int z) const {
  return first_index_[static_cast<std::size_t>(lattice_.n.y) * static_cast<std::size_t>(z)];
}

void FlyingEdges::write_planes(int z_begin, int z_end, int triangles_end,
                               const WeldOutput& out) const {
  const std::uint64_t first_vertex = vertices_before(z_begin),
                      first_index = indices_before(z_begin);
  for_each_plane(z_end - z_begin, *progress_, [&](int k) {
    const int z = z_begin + k;
    write_plane(z, first_vertex, first_index, z < triangles_end, out);
  });
}

void FlyingEdges::write_plane(int z, std::uint64_t first_vertex, std::uint64_t first_index,
                              bool triangles, const WeldOutput& out) const {
  const Vec3i n = lattice_.n;
  const RowSamples in(lattice_, z_offset_);
  const CubeCases& table = CubeCases::get();
  const auto put = [&](std::uint64_t g, const Vertex& v) {
    out.positions[g] = v.position;
    out.normals[g] = v.normal;
    if (out.sources) out.sources[g] = v.source;
  };
  RowRanks counts(8, words_);
  // A row's edge vertices' normals, scaled to unit length together once the row's crossings are
  // placed (unit_normals: the square roots and divisions then overlap).
  const std::size_t row_crossings = 3 * 64 * words_;
  std::vector<double> unscaled(3 * row_crossings);
  double* const normal_x = unscaled.data();
  double* const normal_y = normal_x + row_crossings;
  double* const normal_z = normal_y + row_crossings;
  for (int y = 0; y < n.y; ++y) {
    const std::size_t r = static_cast<std::size_t>(y) + static_cast<std::size_t>(n.y) * z;
    // Row (y + 3, z + 2) is first read three rows on, by the gradient at the upper end of a
    // z-edge of row (y + 3, z) that crosses, or later around a crossing near it (the next plane's
    // reads): the prefetch skips the rows no crossing comes near (37 % of the MRI's), whose lines
    // would only displace ones in use. (Measured on the MRI: about 3 % of the pass.)
    if (y + 3 < n.y && z + 2 < n.z &&
        (!inside_->quiet(y + 3, z) || !inside_->quiet_around(y + 3, z + 2)))
      prefetch_row(lattice_, y + 3, z + 2);
    if (inside_->quiet(y, z)) continue;  // no crossing, no cell crossed
    const std::uint64_t* b = inside_->row(y, z);
    // This row's edge vertices: its x-edge crossings, then its y-edge and z-edge ones.
    const std::uint64_t row_first = first_vertex_[r] - first_vertex;
    std::size_t placed = 0;
    const auto emit = [&](const std::uint64_t* mask, int axis) {
      for (std::size_t w = 0; w < words_; ++w)
        for (std::uint64_t m = mask[w]; m; m &= m - 1) {
          const UnscaledVertex v =
              unscaled_edge_vertex(in, static_cast<int>(64 * w) + std::countr_zero(m), y, z, axis);
          out.positions[row_first + placed] = v.position;
          if (out.sources) out.sources[row_first + placed] = v.source;
          normal_x[placed] = v.normal[0];
          normal_y[placed] = v.normal[1];
          normal_z[placed] = v.normal[2];
          ++placed;
        }
    };
    const bool up_y = y + 1 < n.y, up_z = z + 1 < n.z;
    // Masks 0 (x), 4 (y) and 6 (z) of the cell row starting here are this row's own.
    x_crossings(b, words_, n.x, counts.mask(0));
    emit(counts.mask(0), 0);
    if (up_y) {
      differences(b, inside_->row(y + 1, z), words_, counts.mask(4));
      emit(counts.mask(4), 1);
    }
    if (up_z) {
      differences(b, inside_->row(y, z + 1), words_, counts.mask(6));
      emit(counts.mask(6), 2);
    }
    unit_normals(normal_x, normal_y, normal_z, placed, out.normals + row_first);
    if (!up_y || !up_z) continue;
    // The cell row (y, z): every crossing's number from the masks' running counts.
    const std::uint64_t* rows[4] = {b, inside_->row(y + 1, z), inside_->row(y, z + 1),
                                    inside_->row(y + 1, z + 1)};
    const std::size_t up = static_cast<std::size_t>(n.y);
    const std::size_t row_of[4] = {r, r + 1, r + up, r + up + 1};
    for (int j = 1; j < 4; ++j) x_crossings(rows[j], words_, n.x, counts.mask(j));
    differences(rows[2], rows[3], words_, counts.mask(5));
    differences(rows[1], rows[3], words_, counts.mask(7));
    // (Numbers from first_vertex: the rows' first vertices less the slab's.)
    const auto first = [&](std::size_t row) { return first_vertex_[row] - first_vertex; };
    for (int j = 0; j < 4; ++j) counts.set_base(j, first(row_of[j]));
    counts.set_base(4, first(r) + x_count_[r]);
    counts.set_base(5, first(row_of[2]) + x_count_[row_of[2]]);
    counts.set_base(6, counts.base(4) + y_count_[r]);
    counts.set_base(7, first(row_of[1]) + x_count_[row_of[1]] + y_count_[row_of[1]]);
    counts.count();
    std::uint64_t centre_next = counts.base(6) + z_count_[r];
    std::uint32_t* index = triangles ? out.indices + (first_index_[r] - first_index) : nullptr;
    std::uint32_t* const plane_indices_end =
        triangles ? out.indices + (indices_before(z + 1) - first_index) : nullptr;
    const float* v0 = lattice_.values + in.index(0, y, z);
    for_each_active_cell(rows, words_, n.x, [&](int x, unsigned inside) {
      unsigned joined = 0;
      if (table.ambiguous_faces(inside)) {
        float v[8];
        for (int c = 0; c < 8; ++c)
          v[c] = in.s_of(v0[x + (c & 1) + in.sy * (c >> 1 & 1) + in.sz * (c >> 2 & 1)]);
        joined = table.joined_faces(v, inside);
      }
      const CubeCase& cc = table.lookup(inside, joined);
      // Every crossing's number once, however many triangles use it; ids[kCentre + c] is
      // centre vertex c, which belongs to this cell alone (its crossings are recomputed here,
      // bit for bit those another row writes).
      std::array<std::uint64_t, 8> at;
      counts.ids_at(x, at);
      std::array<std::uint32_t, CubeCase::kCentre + 2> ids =
          edge_ids(at, table.crossed_edges(inside));
      for (int c = 0; c < cc.centre_count; ++c) {
        ids[static_cast<std::size_t>(CubeCase::kCentre + c)] =
            static_cast<std::uint32_t>(centre_next);
        put(centre_next++, centre_vertex(in, cc, c, x, y, z));
      }
      if (!triangles) return;
      const int count = 3 * cc.triangle_count;
      int k = 0;
      // Four triangles' indices at once where the plane's range has room past them (what is
      // written past this cell's own, the next cells of the plane overwrite): a fixed count
      // instead of a loop whose exit is mispredicted every few cells. Triangles past the
      // fourth (a cell has up to 12, fanned from a centre) and the plane's last cells take the
      // loop.
      if (plane_indices_end - index >= 12) {
        for (; k < 12; ++k) index[k] = ids[cc.edges[static_cast<std::size_t>(k)]];
      }
      for (; k < count; ++k) index[k] = ids[cc.edges[static_cast<std::size_t>(k)]];
      index += count;
    });
  }
}

}  // namespace voxfield::detail::mesh
