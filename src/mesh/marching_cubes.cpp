// voxfield — marching cubes on one chunk of cells.
//
// W. E. Lorensen & H. E. Cline, "Marching Cubes: A High Resolution 3D Surface Construction
// Algorithm", SIGGRAPH 1987: each cell's corner signs index a triangulation of the surface inside
// it, with vertices where the surface crosses the cell's edges (linear interpolation of the
// samples). The triangulation comes from cube_cases.h, whose ambiguous faces are settled by Nielson
// & Hamann's asymptotic decider (1991), so the output is crack-free and manifold.
//
// Vertices live on lattice edges and are shared by the up to four cells around each edge; a
// chunk numbers the edges it meets in `scratch` (one slot per axis per sample of its cells).
// Crossings are interpolated from the edge's lower sample to its upper one and normals blend the
// central-difference gradients at both ends, so a chunk and its neighbour compute identical
// vertices for the edges on their common face.
#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

#include "chunked_mesh.h"
#include "cube_cases.h"

namespace voxfield::detail::mesh {

void marching_cubes_chunk(const Lattice& lattice, const ChunkGrid& grid, Vec3i chunk,
                          const Block& block, std::vector<std::int32_t>& scratch, ChunkPart& part) {
  const Box3i cells = grid.cells_of(chunk);
  const Vec3i b = cells.begin;
  const std::size_t ex = static_cast<std::size_t>(cells.end.x - b.x + 1),
                    ey = static_cast<std::size_t>(cells.end.y - b.y + 1);
  scratch.assign(3 * ex * ey * static_cast<std::size_t>(cells.end.z - b.z + 1), -1);
  const CubeCases& table = CubeCases::get();
  const auto& edges = cube_edges();

  // (The lattice point comes as three ints: a Vec3i built on the stack and read back as one 64-bit
  // word stalled store forwarding on every call, a third of this function's time.)
  auto vertex = [&](int px, int py, int pz, int axis) -> std::uint32_t {
    std::int32_t& slot = scratch[3 * (static_cast<std::size_t>(px - b.x) +
                                      ex * (static_cast<std::size_t>(py - b.y) +
                                            ey * static_cast<std::size_t>(pz - b.z))) +
                                 static_cast<std::size_t>(axis)];
    if (slot >= 0) return static_cast<std::uint32_t>(slot);
    const Vec3i p{px, py, pz};
    Vec3i q = p;
    ++q[axis];
    const double s0 = block.s(p.x, p.y, p.z), s1 = block.s(q.x, q.y, q.z);
    const double t = lattice.crossing(p, axis, s0, s1);
    std::array<double, 3> at{static_cast<double>(p.x), static_cast<double>(p.y),
                             static_cast<double>(p.z)};
    at[static_cast<std::size_t>(axis)] += t;
    std::array<double, 3> normal;
    if (lattice.gradient) {
      normal = lattice.exact_normal(lattice_position(lattice, at));
    } else {
      const auto g0 = block.gradient(p.x, p.y, p.z), g1 = block.gradient(q.x, q.y, q.z);
      normal = {g0[0] + t * (g1[0] - g0[0]), g0[1] + t * (g1[1] - g0[1]),
                g0[2] + t * (g1[2] - g0[2])};
    }
    if (normal[0] == 0 && normal[1] == 0 && normal[2] == 0)
      normal[static_cast<std::size_t>(axis)] = s0 < 0 ? 1 : -1;
    bool owned = true, shared = false;
    for (int a = 0; a < 3; ++a) {
      owned &= grid.owner(a, p[a]) == chunk[a];
      if (a != axis && p[a] == b[a] && b[a] > 0) shared = true;
    }
    const std::uint64_t source =
        s0 < 0 ? lattice.index(p.x, p.y, p.z) : lattice.index(q.x, q.y, q.z);
    const std::uint32_t id = part.add(lattice_position(lattice, at), normal,
                                      3 * static_cast<std::uint64_t>(lattice.index(p.x, p.y, p.z)) +
                                          static_cast<std::uint64_t>(axis),
                                      source, owned, owned && shared);
    slot = static_cast<std::int32_t>(id);
    return id;
  };

  // A cell's corner mask from the signs at its two x faces: nibble bit k (row k of the four
  // below) is corner 2k at x and corner 2k + 1 at x + 1.
  static constexpr auto spread = [] {
    std::array<std::uint8_t, 16> t{};
    for (unsigned n = 0; n < 16; ++n)
      t[n] = static_cast<std::uint8_t>((n & 1) | (n & 2) << 1 | (n & 4) << 2 | (n & 8) << 3);
    return t;
  }();
  float v[8];
  const int row_cells = cells.end.x - b.x;
  // Per sample of a row of cells: its four sample rows' inside bits (a cell's x faces), computed
  // for the whole row in one loop the compiler vectorises.
  std::vector<std::uint8_t> faces(static_cast<std::size_t>(row_cells) + 1);
  for (int z = cells.begin.z; z < cells.end.z; ++z)
    for (int y = cells.begin.y; y < cells.end.y; ++y) {
      // Rows whose four sample rows hold one sign only have no surface: most rows, away from it.
      if ((block.row_signs(y, z) | block.row_signs(y + 1, z) | block.row_signs(y, z + 1) |
           block.row_signs(y + 1, z + 1)) != 3)
        continue;
      const float* r[4] = {block.row(b.x, y, z), block.row(b.x, y + 1, z), block.row(b.x, y, z + 1),
                           block.row(b.x, y + 1, z + 1)};
      for (int i = 0; i <= row_cells; ++i)
        faces[static_cast<std::size_t>(i)] =
            static_cast<std::uint8_t>(block.inside(r[0][i]) | block.inside(r[1][i]) << 1 |
                                      block.inside(r[2][i]) << 2 | block.inside(r[3][i]) << 3);
      for (int x = cells.begin.x; x < cells.end.x; ++x) {
        const int i = x - b.x;
        // Eight cells at once whose nine faces are all inside or all outside: none has surface.
        if (i + 8 <= row_cells) {
          std::uint64_t here, next;
          std::memcpy(&here, &faces[static_cast<std::size_t>(i)], 8);
          std::memcpy(&next, &faces[static_cast<std::size_t>(i) + 1], 8);
          if (here == next && (here == 0 || here == 0x0f0f0f0f0f0f0f0full)) {
            x += 7;
            continue;
          }
        }
        const unsigned inside =
            spread[faces[static_cast<std::size_t>(i)]] |
            static_cast<unsigned>(spread[faces[static_cast<std::size_t>(i) + 1]]) << 1;
        if (inside == 0 || inside == 255) continue;
        for (int c = 0; c < 8; ++c) v[c] = block.s_of(r[c >> 1][i + (c & 1)]);
        const CubeCase& cc = table.lookup(inside, table.joined_faces(v, inside));
        // The cell's crossing edges, each looked up (or made) once however many triangles use it.
        std::array<std::uint32_t, 12> ids;
        std::uint32_t known = 0;
        auto edge_vertex = [&](int edge) {
          if (!(known >> edge & 1)) {
            const CubeEdge& e = edges[static_cast<std::size_t>(edge)];
            ids[static_cast<std::size_t>(edge)] =
                vertex(x + (e.from & 1), y + (e.from >> 1 & 1), z + (e.from >> 2 & 1), e.axis);
            known |= 1u << edge;
          }
          return ids[static_cast<std::size_t>(edge)];
        };
        // Centre vertices belong to this cell alone (owned, never looked up by a neighbour).
        std::array<std::uint32_t, 2> centre{};
        for (int c = 0; c < cc.centre_count; ++c) {
          std::array<double, 3> mean{0, 0, 0}, normal{0, 0, 0};
          const int n = cc.centre_sizes[static_cast<std::size_t>(c)];
          std::uint32_t first = 0;
          for (int i = 0; i < n; ++i) {
            const std::uint32_t id = edge_vertex(
                cc.centre_edges[static_cast<std::size_t>(c)][static_cast<std::size_t>(i)]);
            if (i == 0) first = id;
            for (std::size_t a = 0; a < 3; ++a) {
              mean[a] += part.positions[id][a] / static_cast<double>(n);
              normal[a] += part.normals[id][a];
            }
          }
          centre[static_cast<std::size_t>(c)] =
              part.add(mean, normal, ~std::uint64_t{0}, part.sources[first], true, false);
        }
        for (int k = 0; k < 3 * cc.triangle_count; ++k) {
          const int edge = cc.edges[static_cast<std::size_t>(k)];
          part.indices.push_back(edge >= CubeCase::kCentre
                                     ? centre[static_cast<std::size_t>(edge - CubeCase::kCentre)]
                                     : edge_vertex(edge));
        }
      }
    }
}

}  // namespace voxfield::detail::mesh
