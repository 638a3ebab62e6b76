// voxfield — the marching-cubes case table (internal to the mesh module).
//
// Instead of the 256-entry table of Lorensen & Cline ("Marching Cubes: A High Resolution 3D Surface
// Construction Algorithm", SIGGRAPH 1987), which joins the crossings of an ambiguous face one way
// in one cell and the other way in its neighbour (cracks), the table is derived from the cell's
// faces: on each face the crossings are joined into segments, and the segments on the cube's six
// faces chain into closed loops, each triangulated as a fan. A face with two crossings has one
// segment; a face with four (diagonal corners alike) is ambiguous and is decided by Nielson &
// Hamann's asymptotic decider ("The Asymptotic Decider: Resolving the Ambiguity in Marching Cubes",
// IEEE Visualization 1991) from that face's four samples only, so the two cells sharing it decide
// alike. Hence every segment belongs to exactly the two polygons either side of the face (no
// cracks), every crossing to exactly one loop per cell (manifold vertices), and segments are
// oriented from the face's geometry so that loops wind counter-clockwise seen from outside.
// Interior ambiguity (the tunnel of cases 4, 6, 7, 10, 12 and 13 in Chernyaev's 33) is not
// resolved: separate loops stay separate sheets, which keeps the surface a closed 2-manifold.
// Loops are triangulated without diagonals lying in a face (see triangulate_loop in the .cpp).
//
// Numbering: corner c = (c & 1, c >> 1 & 1, c >> 2 & 1). Edge 4a + j runs along axis a from the
// corner with bit a clear to the one with it set; j holds the other two axes' bits, lower axis
// first. Face 2a + s is the face at coordinate s along axis a.
#pragma once

#include <array>
#include <bit>
#include <cstdint>

namespace voxfield::detail::mesh {

struct CubeEdge {
  std::uint8_t from, to;  // corners, `to` = `from` with bit `axis` set
  std::uint8_t axis;
};
const std::array<CubeEdge, 12>& cube_edges();

// The triangles of one cell as crossing edges: up to 12 (a loop through all 12 edges fanned from
// a centre vertex). Index kCentre + c stands for centre vertex c, the mean of the crossings of
// centre_edges[c] (the loop it fans).
struct CubeCase {
  static constexpr int kCentre = 12;
  std::uint8_t triangle_count = 0;
  std::array<std::uint8_t, 36> edges{};
  std::uint8_t centre_count = 0;
  std::array<std::uint8_t, 2> centre_sizes{};
  std::array<std::array<std::uint8_t, 12>, 2> centre_edges{};
};

class CubeCases {
 public:
  static const CubeCases& get();  // built once, on first use (thread-safe)

  // Edges (bit e: cube edge e) whose two corners differ for corner mask `inside`: the edges a
  // cell crosses, so the meshers visit those alone without a branch per edge.
  std::uint16_t crossed_edges(unsigned inside) const { return crossed_[inside]; }
  // Per axis a, the sum over those edges not along a of their corners' coordinate a (0 or 1):
  // what the crossings add up to on a beside the crossing fractions of a's own edges.
  const std::array<std::uint8_t, 3>& corner_sums(unsigned inside) const {
    return corner_sums_[inside];
  }
  // Faces (bit 2a + s) with four crossings for corner mask `inside` (bit c: corner c inside).
  std::uint8_t ambiguous_faces(unsigned inside) const { return ambiguous_[inside]; }
  // The triangulation for `inside` where `joined` (one bit per ambiguous face, in face order,
  // compacted to the ambiguous faces only) says on which faces the two outside corners connect.
  const CubeCase& lookup(unsigned inside, unsigned joined) const {
    return cases_[offset_[inside] + joined];
  }

  // The `joined` bits of `lookup` for corner mask `inside`, decided on each ambiguous face by the
  // asymptotic decider from the cell's eight values v (negative inside, corner c at v[c]): the
  // bilinear interpolant's saddle lies outside when the product of the outside diagonal's values
  // is at least that of the inside diagonal's. Products of the same four samples are computed
  // whichever cell asks, so both cells sharing the face decide alike (ties join the outside).
  unsigned joined_faces(const float* v, unsigned inside) const {
    unsigned joined = 0;
    const unsigned ambiguous = ambiguous_[inside];
    for (int face = 0, bit = 0; face < 6; ++face)
      if (ambiguous >> face & 1) {
        const std::array<std::uint8_t, 4> c = face_corners(face);
        const double d02 = static_cast<double>(v[c[0]]) * v[c[2]];
        const double d13 = static_cast<double>(v[c[1]]) * v[c[3]];
        const bool diagonal02_inside = (inside >> c[0] & 1) != 0;
        if (diagonal02_inside ? d13 >= d02 : d02 >= d13) joined |= 1u << bit;
        ++bit;
      }
    return joined;
  }

  // For one ambiguous face: corners in cyclic order around it (so 0/2 and 1/3 are the diagonals),
  // starting at the face's lowest corner and going first along the face's lower axis.
  static std::array<std::uint8_t, 4> face_corners(int face);

 private:
  CubeCases();
  std::array<std::uint8_t, 256> ambiguous_{};
  std::array<std::uint16_t, 256> crossed_{};
  std::array<std::array<std::uint8_t, 3>, 256> corner_sums_{};
  std::array<std::uint16_t, 257> offset_{};
  std::array<CubeCase, 1024> cases_{};
};

// Surface nets' vertex in the cell's coordinates: the mean of the crossings of the edges a corner
// mask crosses, each edge contributing t_of(edge) (where along it the surface crosses, 0..1) on
// its axis and its corner's fixed coordinates on the other two. Per axis, the sum is the fractions
// of that axis's crossed edges, in edge order, plus the fixed coordinates (an integer, from the
// table): one summation for every path that places these vertices, so that they agree bit for
// bit however t is found. (The table comes in as an argument: a hot caller looks it up once.)
struct CrossingSums {
  double x, y, z;
  int count;  // > 0 for a cell the surface crosses
};
// How crossing_sums reads t_of: for the crossed edges only, or for every edge where t_of gives +0
// for an edge not crossed (which leaves a sum unchanged). The second has no branch and no mask per
// edge: the edges a noisy volume's cells cross are unpredictable, and a mask per edge was a fifth
// of surface nets' whole-volume pass on the noise volume (docs/benchmarks.md).
enum class EdgeReads { kCrossed, kAnyZeroElsewhere };
template <EdgeReads kReads = EdgeReads::kCrossed, class CrossingOf>
CrossingSums crossing_sums(const CubeCases& table, unsigned inside, CrossingOf&& t_of) {
  const unsigned crossed = table.crossed_edges(inside);
  // Edges 4a..4a+3 run along axis a (the numbering above; cube_edges() is built from it).
  double sum[3];
  for (unsigned a = 0; a < 3; ++a) {
    double s = 0;
    for (unsigned j = 0; j < 4; ++j) {
      const unsigned e = 4 * a + j;
      if constexpr (kReads == EdgeReads::kAnyZeroElsewhere) {
        s += t_of(e);
      } else if (crossed >> e & 1) {
        s += t_of(e);
      }
    }
    sum[a] = s + table.corner_sums(inside)[a];
  }
  return {sum[0], sum[1], sum[2], std::popcount(crossed)};
}
// The mean itself: the sums times the count's inverse (the whole-volume pass does a row of cells'
// at once, with the same arithmetic: one division and three products, since that row's placing
// loop is bound by its divisions).
template <class CrossingOf>
std::array<double, 3> crossing_mean(const CubeCases& table, unsigned inside, CrossingOf&& t_of) {
  const CrossingSums s = crossing_sums(table, inside, t_of);
  // (The cell has a crossing: a quad reached it.)
  const double share = 1.0 / s.count;
  return {s.x * share, s.y * share, s.z * share};
}

}  // namespace voxfield::detail::mesh
