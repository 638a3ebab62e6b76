// voxfield — surface nets and dual contouring of a whole dense lattice in Flying Edges' passes.
//
// The dual grid of S. F. F. Gibson, "Constrained Elastic Surface Nets" (MICCAI 1998) and of Ju,
// Losasso, Schaefer & Warren, "Dual Contouring of Hermite Data" (SIGGRAPH 2002) — one vertex per
// cell the surface crosses, one quad per crossed lattice edge joining the four cells around it —
// run in the pass structure of W. Schroeder, R. Maynard & B. Geveci, "Flying Edges: A
// High-Performance Scalable Isocontouring Algorithm" (IEEE LDAV 2015): the samples become rows of
// inside bits (bit_rows.h); each sample row's crossed edges that have four cells around them make
// its quads, and each cell row's cells those quads reach make its vertices, both counted per row
// with whole-word bit operations; prefix sums give every row's first vertex and index; then the
// vertices are written, rows in parallel, and after them the quads (split along the shorter
// diagonal, which reads the vertices' positions). A cell's vertex number is its row's first
// vertex plus the reached cells before it on the row — a population count. Vertices, normals and
// sources are the chunked driver's (dual_grid.cpp's dual_cell_vertex; surface nets find each
// edge's crossing once per sample row and place the vertex with the same arithmetic, dual
// contouring calls it): the triangles are the same, bit for bit, only numbered by row.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "bit_rows.h"
#include "cube_cases.h"
#include "flying_edges.h"
#include "mesh_memory.h"
#include "voxfield/detail/vector_clones.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield::detail::mesh {

bool flying_dual_applies(const Lattice& lattice, const MeshOptions& options) {
  return options.algorithm != Mesher::kMarchingCubes && lattice.values && !lattice.value &&
         !lattice.gradient && !lattice.color;
}

// One sample row's quads: its crossed x-, y- and z-edges that have four cells around them.
struct FlyingDual::Masks {
  std::vector<std::uint64_t> x, y, z;
  explicit Masks(std::size_t words) : x(words), y(words), z(words) {}
};

namespace {

// Bit x of the result is bit x + 1 of m: the cells whose upper corner on x is a mask's bit.
std::uint64_t next_bits(const std::uint64_t* m, std::size_t words, std::size_t w) {
  return m[w] >> 1 | (w + 1 < words ? m[w + 1] << 63 : 0);
}

}  // namespace

void FlyingDual::quads(int y, int z, Masks& m) const {
  const Vec3i n = lattice_.n;
  const std::size_t words = words_;
  std::fill(m.x.begin(), m.x.end(), 0);
  std::fill(m.y.begin(), m.y.end(), 0);
  std::fill(m.z.begin(), m.z.end(), 0);
  // A quad needs the cells on both sides along its two other axes: the edge's other coordinates
  // lie strictly inside the lattice (dual_grid.cpp's rule: cells before and after it) — the whole
  // lattice's, for a slab; rows past the planes held are never asked for (the slab's window).
  const int zg = z + z_offset_, nz = whole_.n.z;
  const bool inner_y = y >= 1 && y <= n.y - 2, inner_z = zg >= 1 && zg <= nz - 2;
  const bool below_y = y <= n.y - 2, below_z = zg <= nz - 2 && z + 1 < n.z;
  const std::uint64_t* b = inside_->row(y, z);
  if (inner_y && inner_z) x_crossings(b, words, n.x, m.x.data());
  const auto inner_x = [&](std::uint64_t* mask) {
    mask[0] &= ~std::uint64_t{1};
    mask[static_cast<std::size_t>(n.x - 1) >> 6] &= ~(std::uint64_t{1} << ((n.x - 1) & 63));
  };
  if (below_y && inner_z) {
    differences(b, inside_->row(y + 1, z), words, m.y.data());
    inner_x(m.y.data());
  }
  if (below_z && inner_y) {
    differences(b, inside_->row(y, z + 1), words, m.z.data());
    inner_x(m.z.data());
  }
}

void FlyingDual::cells(int y, int z, Masks& scratch, std::uint64_t* used) const {
  const Vec3i n = lattice_.n;
  const std::size_t words = words_;
  std::fill(used, used + words, 0);
  // Cell (x, y, z) is reached by the x-edge quads of sample rows (y..y+1, z..z+1) at x, the
  // y-edge quads of rows (y, z..z+1) and the z-edge quads of rows (y..y+1, z) at x or x + 1.
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy) {
      quads(y + dy, z + dz, scratch);
      for (std::size_t w = 0; w < words; ++w) {
        used[w] |= scratch.x[w];
        if (dy == 0) used[w] |= scratch.y[w] | next_bits(scratch.y.data(), words, w);
        if (dz == 0) used[w] |= scratch.z[w] | next_bits(scratch.z.data(), words, w);
      }
    }
  // Only cells that exist (x <= nx - 2).
  const std::size_t last = static_cast<std::size_t>(n.x - 2) >> 6;
  used[last] &= low_bits(static_cast<unsigned>(n.x - 2) & 63) << 1 | 1;
  for (std::size_t w = last + 1; w < words; ++w) used[w] = 0;
}

FlyingDual::FlyingDual(const Lattice& lattice, const MeshOptions& options)
    : FlyingDual(lattice, options, 0, lattice.n.z, 0, lattice.n.z) {}

FlyingDual::FlyingDual(const Lattice& lattice, const MeshOptions& options, int z_offset,
                       int whole_z, int slab_begin, int slab_end)
    : lattice_(lattice),
      whole_(lattice),
      z_offset_(z_offset),
      place_(options.algorithm == Mesher::kSurfaceNets ? surface_nets_vertex
                                                       : dual_contouring_vertex),
      progress_(std::make_unique<Progress>(
          options.interrupter,
          options.algorithm == Mesher::kSurfaceNets ? "surface nets" : "dual contouring",
          4 * static_cast<std::int64_t>(lattice.n.z))) {
  const Vec3i n = lattice.n;
  whole_.n.z = whole_z;
  whole_.values = nullptr;
  // Cells exist below the whole lattice's last plane; a slab's quads use the cell plane before it.
  quads_begin_ = slab_begin;
  quads_end_ = slab_end;
  cells_begin_ = slab_begin + z_offset > 0 ? slab_begin - 1 : slab_begin;
  cells_end_ = std::min(slab_end, whole_z - 1 - z_offset);
  const std::size_t rows = static_cast<std::size_t>(n.y) * static_cast<std::size_t>(n.z);
  require_memory(mul_sat(rows, 2 * 8), 0, "mesh", "the dual mesher's row bookkeeping");
  inside_ = std::make_unique<InsideBits>(lattice, *progress_, z_offset);
  words_ = inside_->words();
  require_memory(mul_sat(mul_sat(rows, words_), 8), 0, "mesh", "the dual mesher's reached cells");
  resize_on_huge_pages(reached_, rows * words_);
  block_.view_planes(whole_, lattice.values, z_offset);
  Progress& progress = *progress_;
  count_rows(
      n.z, rows, progress, [this](int z) { count_plane(z); }, first_vertex_, first_index_);
  vertices_ = first_vertex_[rows];
  indices_ = first_index_[rows];
}

const std::uint64_t* FlyingDual::reached(int y, int z) const {
  return reached_.data() +
         words_ * (static_cast<std::size_t>(y) + static_cast<std::size_t>(lattice_.n.y) * z);
}

std::uint64_t FlyingDual::vertices_before(int z) const {
  return first_vertex_[static_cast<std::size_t>(lattice_.n.y) * static_cast<std::size_t>(z)];
}

std::uint64_t FlyingDual::indices_before(int z) const {
  return first_index_[static_cast<std::size_t>(lattice_.n.y) * static_cast<std::size_t>(z)];
}

void FlyingDual::count_plane(int z) {
  const Vec3i n = lattice_.n;
  const bool counts_quads = z >= quads_begin_ && z < quads_end_,
             counts_cells = z >= cells_begin_ && z < cells_end_;
  if (!counts_quads && !counts_cells) return;  // its rows count nothing
  Masks m(words_), scratch(words_);
  for (int y = 0; y < n.y; ++y) {
    const std::size_t r = static_cast<std::size_t>(y) + static_cast<std::size_t>(n.y) * z;
    // No quad starts on a quiet row and no quad reaches its cell row (rows y..y+1, z..z+1 all
    // alike): its counts and reached cells stay 0.
    if (inside_->quiet(y, z)) continue;
    if (counts_quads) {
      quads(y, z, m);
      first_index_[r + 1] = 6 * (population(m.x.data(), words_) + population(m.y.data(), words_) +
                                 population(m.z.data(), words_));
    }
    if (y + 1 < n.y && counts_cells) {
      std::uint64_t* used = reached_.data() + words_ * r;  // this plane's own rows
      cells(y, z, scratch, used);
      first_vertex_[r + 1] = population(used, words_);
    }
  }
}

void FlyingDual::write(const WeldOutput& out) const {
  Progress& progress = *progress_;
  const int planes = lattice_.n.z;
  // The vertices first: a quad's diagonal is chosen from its four vertices' positions.
  for_each_plane(planes, progress, [&](int z) {
    if (place_ == surface_nets_vertex)
      write_surface_nets_vertices(z, out);
    else
      write_vertices(z, out);
  });
  for_each_plane(planes, progress, [&](int z) { write_quads(z, out); });
}

void FlyingDual::write_vertices(int z, const WeldOutput& out) const {
  const Vec3i n = lattice_.n;
  if (z < cells_begin_ || z >= cells_end_) return;
  const int zg = z + z_offset_;
  for (int y = 0; y + 1 < n.y; ++y) {
    const std::size_t r = static_cast<std::size_t>(y) + static_cast<std::size_t>(n.y) * z;
    if (y + 3 < n.y && z + 2 < n.z) prefetch_row(lattice_, y + 3, z + 2);
    const std::uint64_t* used = reached(y, z);
    std::uint64_t g = first_vertex_[r];
    for (std::size_t w = 0; w < words_; ++w)
      for (std::uint64_t m = used[w]; m; m &= m - 1) {
        const int x = static_cast<int>(64 * w) + std::countr_zero(m);
        const DualVertex v = dual_cell_vertex(block_, whole_, x, y, zg, place_, out.sources);
        out.positions[g] = {static_cast<float>(v.position[0]), static_cast<float>(v.position[1]),
                            static_cast<float>(v.position[2])};
        out.normals[g] = unit_normal(v.normal);
        if (out.sources) out.sources[g] = v.source;
        ++g;
      }
  }
}

namespace {

// A row of cells' surface-nets vertices, placed together: gathered cell by cell (corner values,
// crossing sums), placed in one loop over the row free of branches — the vertices' divisions and
// square roots then overlap and vectorise instead of each waiting on the one before — and
// scattered with the rare cases. The arithmetic is dual_vertex_at's and unit_normal's, operation
// for operation, so the vertices are the chunked driver's bit for bit.
struct CellRow {
  std::array<std::vector<double>, 8> v;  // the corners' s values
  std::vector<double> x, count;          // the cell's x; its crossed edges
  std::array<std::vector<double>, 3> sum, mean;
  std::array<std::vector<float>, 3> position, normal;
  // The gradient is zero there: saddle_normal() applies. (As wide as a double: a narrower flag
  // would keep the placing loop from vectorising.)
  std::vector<std::int64_t> saddle;
  explicit CellRow(std::size_t cells) : x(cells), count(cells), saddle(cells) {
    for (auto& a : v) a.resize(cells);
    for (std::size_t a = 0; a < 3; ++a) {
      sum[a].resize(cells), mean[a].resize(cells);
      position[a].resize(cells), normal[a].resize(cells);
    }
  }
  // Places cells [0, k) of cell row (y, z). (Measured on the noise volume: a second copy in AVX2
  // takes 3.6-6 % off surface nets' whole pass; the passes around it gained nothing from AVX2.)
  VOXFIELD_AVX2_CLONE void place(const Lattice& l, int y, int z, std::size_t k) {
    // Raw pointers that promise not to alias (through the vectors, every store could move their
    // own data pointers), and ivdep: without them GCC 12 neither keeps the pointers in registers
    // nor vectorises the loop.
    const double* __restrict c0 = v[0].data();
    const double* __restrict c1 = v[1].data();
    const double* __restrict c2 = v[2].data();
    const double* __restrict c3 = v[3].data();
    const double* __restrict c4 = v[4].data();
    const double* __restrict c5 = v[5].data();
    const double* __restrict c6 = v[6].data();
    const double* __restrict c7 = v[7].data();
    const double* __restrict cx = x.data();
    const double* __restrict cn = count.data();
    const double* __restrict s0 = sum[0].data();
    const double* __restrict s1 = sum[1].data();
    const double* __restrict s2 = sum[2].data();
    double* __restrict m0 = mean[0].data();
    double* __restrict m1 = mean[1].data();
    double* __restrict m2 = mean[2].data();
    float* __restrict p0 = position[0].data();
    float* __restrict p1 = position[1].data();
    float* __restrict p2 = position[2].data();
    float* __restrict n0 = normal[0].data();
    float* __restrict n1 = normal[1].data();
    float* __restrict n2 = normal[2].data();
    std::int64_t* __restrict flat = saddle.data();
    const double qy = y, qz = z;
    const std::array<double, 3> origin = l.origin, spacing = l.spacing;
    constexpr double kMax = std::numeric_limits<double>::max();
    // (GCC only: clang, which builds voxfield's sanitizer and fuzzing presets, warns where it
    // cannot vectorise a loop it was asked to, and speed is not measured there.)
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC ivdep
#endif
    for (std::size_t i = 0; i < k; ++i) {
      const double share = 1 / cn[i];  // crossing_mean's arithmetic
      const double u = s0[i] * share, w1 = s1[i] * share, w2 = s2[i] * share;
      m0[i] = u, m1[i] = w1, m2[i] = w2;
      const double c[8] = {c0[i], c1[i], c2[i], c3[i], c4[i], c5[i], c6[i], c7[i]};
      const std::array<double, 3> n = trilinear_gradient(c, u, w1, w2, spacing);
      p0[i] = static_cast<float>(origin[0] + (cx[i] + u) * spacing[0]);
      p1[i] = static_cast<float>(origin[1] + (qy + w1) * spacing[1]);
      p2[i] = static_cast<float>(origin[2] + (qz + w2) * spacing[2]);
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      const bool unit = length > 0 && length <= kMax;  // unit_normal's test (NaN fails both)
      const double inverse = 1 / length;               // unit_normal's arithmetic
      n0[i] = unit ? static_cast<float>(n[0] * inverse) : 0.0f;
      n1[i] = unit ? static_cast<float>(n[1] * inverse) : 0.0f;
      n2[i] = unit ? static_cast<float>(n[2] * inverse) : 1.0f;
      flat[i] = n[0] == 0 && n[1] == 0 && n[2] == 0;
    }
  }
};

}  // namespace

// Surface nets' vertices of plane z with each crossed edge interpolated once: a cell's vertex is
// the mean of its edges' crossings, and every edge is shared by four cells, so the crossings are
// found per sample row first (t = s0 / (s0 - s1), surface_nets_vertex's arithmetic on the same
// values) and each cell then sums its edges' in surface_nets_vertex's order: the same vertices,
// bit for bit, at a quarter of the divisions.
void FlyingDual::write_surface_nets_vertices(int z, const WeldOutput& out) const {
  const Vec3i n = lattice_.n;
  if (z < cells_begin_ || z >= cells_end_) return;
  const int zg = z + z_offset_;  // samples are read, and vertices placed, in the whole lattice
  const std::size_t words = words_, nx = static_cast<std::size_t>(n.x);
  // Crossings of x-edges on sample rows (y', z + dz), kept for two y' (by parity) per layer dz;
  // of z-edges from rows (y', z) to (y', z + 1), two y'; of y-edges from (y, z + dz) to
  // (y + 1, z + dz), the current y only. Entries of edges not crossed hold +0, which the cells'
  // sums add without a mask (crossing_sums' kAnyZeroElsewhere): clearing a row's array costs less
  // than masking each of a cell's twelve reads (measured: a fifth of surface nets' whole pass on
  // the noise volume).
  std::vector<double> store(8 * nx);
  double* tx[2][2] = {{&store[0], &store[nx]}, {&store[2 * nx], &store[3 * nx]}};
  double* tz[2] = {&store[4 * nx], &store[5 * nx]};
  double* ty[2] = {&store[6 * nx], &store[7 * nx]};
  std::vector<std::uint64_t> mask(words);
  // t along each crossed edge from r0[x] to r1[x], for x below `end`.
  const auto crossings = [&](const float* r0, const float* r1, int end, double* t) {
    std::fill_n(t, nx, 0.0);
    for (std::size_t w = 0; w < words; ++w)
      for (std::uint64_t m = mask[w]; m; m &= m - 1) {
        const int x = static_cast<int>(64 * w) + std::countr_zero(m);
        if (x >= end) return;
        const double s0 = block_.s_of(r0[x]), s1 = block_.s_of(r1[x]);
        t[x] = s0 / (s0 - s1);
      }
  };
  const auto along_x = [&](int y, int zz, double* t) {
    x_crossings(inside_->row(y, zz), words, n.x, mask.data());
    const float* r = block_.row(0, y, zz + z_offset_);
    crossings(r, r + 1, n.x - 1, t);
  };
  const auto between = [&](int y0, int z0, int y1, int z1, double* t) {
    differences(inside_->row(y0, z0), inside_->row(y1, z1), words, mask.data());
    crossings(block_.row(0, y0, z0 + z_offset_), block_.row(0, y1, z1 + z_offset_), n.x, t);
  };
  along_x(0, z, tx[0][0]);
  along_x(0, z + 1, tx[1][0]);
  between(0, z, 0, z + 1, tz[0]);
  const CubeCases& table = CubeCases::get();
  const auto& edges = cube_edges();
  CellRow cells(nx);
  for (int y = 0; y + 1 < n.y; ++y) {
    const int p = y & 1, q = p ^ 1;
    along_x(y + 1, z, tx[0][q]);
    along_x(y + 1, z + 1, tx[1][q]);
    between(y + 1, z, y + 1, z + 1, tz[q]);
    const std::size_t r = static_cast<std::size_t>(y) + static_cast<std::size_t>(n.y) * z;
    const std::uint64_t* used = reached(y, z);
    if (population(used, words) == 0) continue;
    between(y, z, y + 1, z, ty[0]);
    between(y, z + 1, y + 1, z + 1, ty[1]);
    // Edge e of a cell at x reads its crossing at tp[e][x].
    const double* tp[12];
    for (std::size_t e = 0; e < 12; ++e) {
      const int from = edges[e].from, dx = from & 1, dy = from >> 1 & 1, dz = from >> 2 & 1;
      const int yp = dy ? q : p;
      tp[e] = edges[e].axis == 0 ? tx[dz][yp] : edges[e].axis == 1 ? ty[dz] + dx : tz[yp] + dx;
    }
    const float* row[4] = {block_.row(0, y, zg), block_.row(0, y + 1, zg), block_.row(0, y, zg + 1),
                           block_.row(0, y + 1, zg + 1)};
    // Surface nets read rows z and z + 1 only; row (y + 3, z + 2) is the next plane's, asked
    // for a plane ahead. (Gating it on the rows around it, as marching cubes does, or asking for
    // row (y + 3, z + 1) instead made no difference on the noise volume.)
    if (y + 3 < n.y && z + 2 < n.z) prefetch_row(lattice_, y + 3, z + 2);
    // Gather: each reached cell's corner values and crossing sums, in cell order.
    std::size_t k = 0;
    for (std::size_t w = 0; w < words; ++w)
      for (std::uint64_t m = used[w]; m; m &= m - 1) {
        const int x = static_cast<int>(64 * w) + std::countr_zero(m);
        double v[8];
        unsigned inside = 0;
        for (unsigned c = 0; c < 8; ++c) {
          v[c] = block_.s_of(row[c >> 1][x + (c & 1)]);
          inside |= static_cast<unsigned>(v[c] < 0) << c;
        }
        const CrossingSums sums = crossing_sums<EdgeReads::kAnyZeroElsewhere>(
            table, inside, [&](unsigned e) { return tp[e][x]; });
        for (std::size_t c = 0; c < 8; ++c) cells.v[c][k] = v[c];
        cells.x[k] = x;
        cells.sum[0][k] = sums.x, cells.sum[1][k] = sums.y, cells.sum[2][k] = sums.z;
        cells.count[k] = sums.count;
        ++k;
      }
    cells.place(whole_, y, zg, k);
    // Scatter, with dual_vertex_at's rare cases: saddles and colour sources.
    std::uint64_t g = first_vertex_[r];
    for (std::size_t i = 0; i < k; ++i, ++g) {
      out.positions[g] = {cells.position[0][i], cells.position[1][i], cells.position[2][i]};
      out.normals[g] = {cells.normal[0][i], cells.normal[1][i], cells.normal[2][i]};
      if (!cells.saddle[i] && !out.sources) continue;
      double v[8];
      for (std::size_t c = 0; c < 8; ++c) v[c] = cells.v[c][i];
      const double u = cells.mean[0][i], w1 = cells.mean[1][i], w2 = cells.mean[2][i];
      if (cells.saddle[i])
        out.normals[g] = unit_normal(saddle_normal(v, u, w1, w2, lattice_.spacing));
      if (out.sources)
        out.sources[g] =
            nearest_inside_corner(whole_, static_cast<int>(cells.x[i]), y, zg, v, u, w1, w2);
    }
  }
}

void FlyingDual::write_quads(int z, const WeldOutput& out) const {
  const Vec3i n = lattice_.n;
  if (z < quads_begin_ || z >= quads_end_) return;
  Masks m(words_);
  // The reached cells of the cell rows around a sample row's edges: 0 (y - 1, z - 1),
  // 1 (y, z - 1), 2 (y, z), 3 (y - 1, z), each with its running counts; a row past the lattice's
  // cells has none.
  RowRanks ranks(4, words_);
  const std::vector<std::uint64_t> none(words_, 0);
  const auto distance2 = [&](std::uint32_t i, std::uint32_t j) {
    double d = 0;
    for (std::size_t a = 0; a < 3; ++a) {
      const double c = static_cast<double>(out.positions[i][a]) - out.positions[j][a];
      d += c * c;
    }
    return d;
  };
  for (int y = 0; y < n.y; ++y) {
    const std::size_t r = static_cast<std::size_t>(y) + static_cast<std::size_t>(n.y) * z;
    std::uint32_t* index = out.indices + first_index_[r];
    std::uint32_t* const end = out.indices + first_index_[r + 1];
    if (index == end) continue;
    quads(y, z, m);
    const int cy[4] = {y - 1, y, y, y - 1}, cz[4] = {z - 1, z - 1, z, z};
    for (int k = 0; k < 4; ++k) {
      if (cy[k] < 0 || cz[k] < cells_begin_ || cy[k] > n.y - 2 || cz[k] >= cells_end_) {
        ranks.borrow(k, none.data());
        ranks.set_base(k, 0);
        continue;
      }
      ranks.borrow(k, reached(cy[k], cz[k]));
      ranks.set_base(
          k,
          first_vertex_[static_cast<std::size_t>(cy[k]) + static_cast<std::size_t>(n.y) * cz[k]]);
    }
    ranks.count();
    const std::uint64_t* b = inside_->row(y, z);
    const auto quad = [&](std::uint32_t v00, std::uint32_t v10, std::uint32_t v11,
                          std::uint32_t v01, bool in0) {
      index = put_quad(index, v00, v10, v11, v01, in0, distance2);
    };
    const auto id = [&](int k, int x) { return static_cast<std::uint32_t>(ranks.id(k, x)); };
    // The row's x-edge quads, then its y- and z-edge ones: a loop per axis rather than a test
    // per crossed edge of which axes it is crossed on (unpredictable on a noisy volume).
    const auto each = [&](const std::vector<std::uint64_t>& mask, auto&& f) {
      for (std::size_t w = 0; w < words_; ++w)
        for (std::uint64_t bits = mask[w]; bits; bits &= bits - 1) {
          const int bit = std::countr_zero(bits);
          f(static_cast<int>(64 * w) + bit, (b[w] >> bit & 1) != 0);
        }
    };
    // Cells (x, y-1, z-1), (x, y, z-1), (x, y, z), (x, y-1, z).
    each(m.x, [&](int x, bool in0) { quad(id(0, x), id(1, x), id(2, x), id(3, x), in0); });
    // Cells (x-1, y, z-1), (x-1, y, z), (x, y, z), (x, y, z-1).
    each(m.y, [&](int x, bool in0) { quad(id(1, x - 1), id(2, x - 1), id(2, x), id(1, x), in0); });
    // Cells (x-1, y-1, z), (x, y-1, z), (x, y, z), (x-1, y, z).
    each(m.z, [&](int x, bool in0) { quad(id(3, x - 1), id(3, x), id(2, x), id(2, x - 1), in0); });
  }
}

}  // namespace voxfield::detail::mesh
