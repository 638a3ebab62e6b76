// voxfield — meshes on the dual grid, shared by surface nets and dual contouring: one vertex per
// cell the surface crosses, placed by the mesher (surface_nets.cpp, dual_contouring.cpp), and one
// quad per lattice edge the surface crosses, joining the four cells around it, split into two
// triangles along its shorter diagonal. Normals are the gradient of the cell's trilinear
// interpolant at the vertex.
//
// A chunk emits the quads of the edges starting in its own cells; the cells around them reach one
// cell before the chunk, whose vertices the chunk computes (identically to their owner, for the
// diagonal test) and the weld replaces with the owner's.
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "chunked_mesh.h"

namespace voxfield::detail::mesh {

DualVertex dual_cell_vertex(const Block& block, const Lattice& lattice, int qx, int qy, int qz,
                            CellVertex place, bool with_source) {
  const Vec3i q{qx, qy, qz};
  double v[8];
  for (int c = 0; c < 8; ++c) v[c] = block.s(q.x + (c & 1), q.y + (c >> 1 & 1), q.z + (c >> 2 & 1));
  return dual_vertex_at(lattice, qx, qy, qz, v, place(block, lattice, q, v), with_source);
}

DualVertex dual_vertex_at(const Lattice& lattice, int qx, int qy, int qz, const double* v,
                          const std::array<double, 3>& mean, bool with_source) {
  const double u = mean[0], w1 = mean[1], w2 = mean[2];
  const std::array<double, 3> position = lattice_position(lattice, {qx + u, qy + w1, qz + w2});
  std::array<double, 3> normal = lattice.gradient
                                     ? lattice.exact_normal(position)
                                     : trilinear_gradient(v, u, w1, w2, lattice.spacing);
  if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0)
    normal = saddle_normal(v, u, w1, w2, lattice.spacing);
  return {position, normal,
          with_source ? nearest_inside_corner(lattice, qx, qy, qz, v, u, w1, w2) : 0};
}

std::array<double, 3> saddle_normal(const double* v, double u, double w1, double w2,
                                    const std::array<double, 3>& spacing) {
  std::array<double, 3> inside{0, 0, 0};
  int count = 0;
  for (int c = 0; c < 8; ++c)
    if (v[c] < 0) {
      inside[0] += c & 1, inside[1] += c >> 1 & 1, inside[2] += c >> 2 & 1;
      ++count;
    }
  const std::array<double, 3> at{u, w1, w2};
  std::array<double, 3> normal;
  for (std::size_t a = 0; a < 3; ++a) normal[a] = (at[a] - inside[a] / count) * spacing[a];
  return normal;
}

std::uint64_t nearest_inside_corner(const Lattice& lattice, int qx, int qy, int qz, const double* v,
                                    double u, double w1, double w2) {
  int nearest = -1;
  double best = 1e9;
  for (int c = 0; c < 8; ++c) {
    if (!(v[c] < 0)) continue;
    const double dx = (c & 1) - u, dy = (c >> 1 & 1) - w1, dz = (c >> 2 & 1) - w2;
    const double d = dx * dx + dy * dy + dz * dz;
    if (d < best) best = d, nearest = c;
  }
  return lattice.index(qx + (nearest & 1), qy + (nearest >> 1 & 1), qz + (nearest >> 2 & 1));
}

void dual_grid_chunk(const Lattice& lattice, const ChunkGrid& grid, Vec3i chunk, const Block& block,
                     std::vector<std::int32_t>& scratch, ChunkPart& part, CellVertex place) {
  const Box3i cells = grid.cells_of(chunk);
  Vec3i lo;  // cells with a vertex slot: one before the chunk where the lattice has it
  for (int a = 0; a < 3; ++a) lo[a] = std::max(cells.begin[a] - 1, 0);
  const std::size_t ex = static_cast<std::size_t>(cells.end.x - lo.x),
                    ey = static_cast<std::size_t>(cells.end.y - lo.y);
  scratch.assign(ex * ey * static_cast<std::size_t>(cells.end.z - lo.z), -1);

  // (The cell comes as three ints: a Vec3i built on the stack and read back as one 64-bit word
  // stalls store forwarding on every call.)
  auto vertex = [&](int qx, int qy, int qz) -> std::uint32_t {
    std::int32_t& slot = scratch[static_cast<std::size_t>(qx - lo.x) +
                                 ex * (static_cast<std::size_t>(qy - lo.y) +
                                       ey * static_cast<std::size_t>(qz - lo.z))];
    if (slot >= 0) return static_cast<std::uint32_t>(slot);
    const DualVertex v = dual_cell_vertex(block, lattice, qx, qy, qz, place, true);
    const Vec3i q{qx, qy, qz};
    bool owned = true, shared = false;
    for (int a = 0; a < 3; ++a) {
      owned &= grid.owner(a, q[a]) == chunk[a];
      if (q[a] == cells.end[a] - 1 && cells.end[a] < grid.cells[a]) shared = true;
    }
    const std::uint32_t id = part.add(v.position, v.normal, lattice.index(q.x, q.y, q.z), v.source,
                                      owned, owned && shared);
    slot = static_cast<std::int32_t>(id);
    return id;
  };
  auto distance2 = [&](std::uint32_t i, std::uint32_t j) {
    double d = 0;
    for (int a = 0; a < 3; ++a) {
      const double c = static_cast<double>(part.positions[i][static_cast<std::size_t>(a)]) -
                       part.positions[j][static_cast<std::size_t>(a)];
      d += c * c;
    }
    return d;
  };

  // One quad for the lattice edge from p along `a` when it is crossed: the four cells around the
  // edge, counter-clockwise seen from +a ((0,0), (1,0), (1,1), (0,1) in (b, c) offsets, with
  // e_b x e_c = e_a), split along the shorter diagonal, turned over when the outside is towards -a.
  auto quad = [&](std::uint32_t v00, std::uint32_t v10, std::uint32_t v11, std::uint32_t v01,
                  bool in0) {
    const std::size_t at = part.indices.size();
    part.indices.resize(at + 6);
    put_quad(part.indices.data() + at, v00, v10, v11, v01, in0, distance2);
  };
  const int row_cells = cells.end.x - cells.begin.x;
  // Per cell of a row: the inside bits of its sample and of the next along x, y and z (bits 0..3),
  // computed for the whole row in one loop the compiler vectorises.
  std::vector<std::uint8_t> signs(static_cast<std::size_t>(row_cells));
  for (int z = cells.begin.z; z < cells.end.z; ++z)
    for (int y = cells.begin.y; y < cells.end.y; ++y) {
      // The edges starting in this row of cells join samples of rows (y, z), (y + 1, z) and
      // (y, z + 1) only: when those rows hold one sign, no edge of the row is crossed.
      if ((block.row_signs(y, z) | block.row_signs(y + 1, z) | block.row_signs(y, z + 1)) != 3)
        continue;
      const float* r0 = block.row(cells.begin.x, y, z);
      const float* ry = block.row(cells.begin.x, y + 1, z);
      const float* rz = block.row(cells.begin.x, y, z + 1);
      for (int i = 0; i < row_cells; ++i)
        signs[static_cast<std::size_t>(i)] =
            static_cast<std::uint8_t>(block.inside(r0[i]) | block.inside(r0[i + 1]) << 1 |
                                      block.inside(ry[i]) << 2 | block.inside(rz[i]) << 3);
      for (int i = 0; i < row_cells; ++i) {
        // Eight cells at once whose edges join samples of one sign: no quad.
        if (i + 8 <= row_cells) {
          std::uint64_t w;
          std::memcpy(&w, &signs[static_cast<std::size_t>(i)], 8);
          if (w == 0 || w == 0x0f0f0f0f0f0f0f0full) {
            i += 7;
            continue;
          }
        }
        const unsigned sg = signs[static_cast<std::size_t>(i)];
        if (sg == 0 || sg == 15) continue;
        const int x = cells.begin.x + i;
        const bool in0 = (sg & 1) != 0;
        // Along x (b = y, c = z), along y (b = z, c = x), along z (b = x, c = y); a quad needs
        // the cells before p on its two other axes.
        // (Vertices are made in the order (0,0), (1,0), (1,1), (0,1): the chunk's numbering.)
        if (in0 != ((sg >> 1 & 1) != 0) && y > 0 && z > 0) {
          const std::uint32_t v00 = vertex(x, y - 1, z - 1), v10 = vertex(x, y, z - 1),
                              v11 = vertex(x, y, z), v01 = vertex(x, y - 1, z);
          quad(v00, v10, v11, v01, in0);
        }
        if (in0 != ((sg >> 2 & 1) != 0) && z > 0 && x > 0) {
          const std::uint32_t v00 = vertex(x - 1, y, z - 1), v10 = vertex(x - 1, y, z),
                              v11 = vertex(x, y, z), v01 = vertex(x, y, z - 1);
          quad(v00, v10, v11, v01, in0);
        }
        if (in0 != ((sg >> 3 & 1) != 0) && x > 0 && y > 0) {
          const std::uint32_t v00 = vertex(x - 1, y - 1, z), v10 = vertex(x, y - 1, z),
                              v11 = vertex(x, y, z), v01 = vertex(x - 1, y, z);
          quad(v00, v10, v11, v01, in0);
        }
      }
    }
}

}  // namespace voxfield::detail::mesh
