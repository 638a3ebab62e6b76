// voxfield — builds the marching-cubes case table from the cube's faces (see cube_cases.h for why
// and for the numbering).
#include "cube_cases.h"

#include <stdexcept>
#include <vector>

namespace voxfield::detail::mesh {

namespace {

using Vec = std::array<int, 3>;  // in half units: corners at 0 or 2, edge midpoints at 1

Vec corner_position(int c) {
  return {2 * (c & 1), 2 * (c >> 1 & 1), 2 * (c >> 2 & 1)};
}

Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
int dot(const Vec& a, const Vec& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

std::array<CubeEdge, 12> make_edges() {
  std::array<CubeEdge, 12> edges{};
  for (int axis = 0; axis < 3; ++axis) {
    const int lo = axis == 0 ? 1 : 0, hi = axis == 2 ? 1 : 2;  // the other two axes, in order
    for (int j = 0; j < 4; ++j) {
      const int from = (j & 1) << lo | (j >> 1 & 1) << hi;
      edges[static_cast<std::size_t>(4 * axis + j)] = {static_cast<std::uint8_t>(from),
                                                       static_cast<std::uint8_t>(from | 1 << axis),
                                                       static_cast<std::uint8_t>(axis)};
    }
  }
  return edges;
}

int edge_between(int c0, int c1) {
  const auto& edges = cube_edges();
  for (int e = 0; e < 12; ++e) {
    const CubeEdge& ce = edges[static_cast<std::size_t>(e)];
    if ((ce.from == c0 && ce.to == c1) || (ce.from == c1 && ce.to == c0)) return e;
  }
  throw std::logic_error("cube_cases: corners are not adjacent");
}

// Whether two cube edges lie on a common face.
bool share_face(int e0, int e1) {
  const auto& edges = cube_edges();
  const CubeEdge &a = edges[static_cast<std::size_t>(e0)], &b = edges[static_cast<std::size_t>(e1)];
  for (int axis = 0; axis < 3; ++axis) {
    if (axis == a.axis || axis == b.axis)
      continue;  // a face across `axis` holds edges along the others
    if ((a.from >> axis & 1) == (b.from >> axis & 1)) return true;
  }
  return false;
}

// Segment on `face` between the crossings of edges e0 and e1, oriented so that the loop it belongs
// to winds counter-clockwise seen from outside. With n the face's outward normal and N pointing
// from the segment towards the face's outside corners, the surface's boundary runs along N x n
// (the polygon then lies on its left seen from outside, i.e. inside the cube). At each crossing,
// N is the direction along its edge towards the outside corner; the two are summed.
std::pair<int, int> oriented_segment(int face, int e0, int e1, unsigned inside) {
  const auto& edges = cube_edges();
  const int axis = face / 2, side = face % 2;
  Vec n{0, 0, 0};
  n[static_cast<std::size_t>(axis)] = side ? 1 : -1;
  auto towards_outside = [&](int e) {
    const CubeEdge& ce = edges[static_cast<std::size_t>(e)];
    Vec d{0, 0, 0};
    d[ce.axis] = (inside >> ce.to & 1) ? -1 : 1;  // from the inside corner to the outside one
    return d;
  };
  auto midpoint = [&](int e) {
    const CubeEdge& ce = edges[static_cast<std::size_t>(e)];
    const Vec a = corner_position(ce.from), b = corner_position(ce.to);
    return Vec{(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2};
  };
  const Vec t0 = cross(towards_outside(e0), n), t1 = cross(towards_outside(e1), n);
  const Vec along{t0[0] + t1[0], t0[1] + t1[1], t0[2] + t1[2]};
  const Vec p0 = midpoint(e0), p1 = midpoint(e1);
  const int score = dot(along, Vec{p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]});
  if (score == 0) throw std::logic_error("cube_cases: segment orientation undecided");
  return score > 0 ? std::pair{e0, e1} : std::pair{e1, e0};
}

// Adds the triangles of one loop (crossings in counter-clockwise order seen from outside). A
// diagonal between two crossings on one cube face lies in that face, where the neighbouring cell
// may draw the same diagonal for its own loop (an edge of four triangles), so the triangulation
// uses only diagonals that leave the faces, found by dynamic programming over the polygon's
// sub-chains. Long loops of multiply ambiguous cells have none; they are fanned from an extra
// vertex inside the cell instead (as Lewiner et al.'s MC33 does for its interior cases).
void triangulate_loop(const std::vector<int>& loop, CubeCase& out) {
  const int n = static_cast<int>(loop.size());
  auto allowed = [&](int i, int j) {
    return j - i == 1 || (i == 0 && j == n - 1) ||
           !share_face(loop[static_cast<std::size_t>(i)], loop[static_cast<std::size_t>(j)]);
  };
  // split[i][j]: the apex k of the triangle on chord (i, j) triangulating the chain i..j, or -1.
  std::array<std::array<int, 12>, 12> split;
  for (auto& row : split) row.fill(-1);
  for (int len = 2; len < n; ++len)
    for (int i = 0; i + len < n; ++i) {
      const int j = i + len;
      if (!allowed(i, j)) continue;
      for (int k = i + 1;
           k < j && split[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] < 0; ++k) {
        const bool left =
            k - i == 1 || split[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] >= 0;
        const bool right =
            j - k == 1 || split[static_cast<std::size_t>(k)][static_cast<std::size_t>(j)] >= 0;
        if (left && right) split[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = k;
      }
    }
  auto emit = [&](int a, int b, int c) {
    const std::size_t t = out.triangle_count++;
    out.edges[3 * t] = static_cast<std::uint8_t>(a);
    out.edges[3 * t + 1] = static_cast<std::uint8_t>(b);
    out.edges[3 * t + 2] = static_cast<std::uint8_t>(c);
  };
  if (n == 3 || split[0][static_cast<std::size_t>(n - 1)] >= 0) {
    std::vector<std::pair<int, int>> chains{{0, n - 1}};
    while (!chains.empty()) {
      const auto [i, j] = chains.back();
      chains.pop_back();
      const int k = n == 3 ? 1 : split[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)];
      emit(loop[static_cast<std::size_t>(i)], loop[static_cast<std::size_t>(k)],
           loop[static_cast<std::size_t>(j)]);
      if (k - i > 1) chains.push_back({i, k});
      if (j - k > 1) chains.push_back({k, j});
    }
    return;
  }
  if (out.centre_count == out.centre_sizes.size())
    throw std::logic_error("cube_cases: too many centre vertices");
  const std::size_t c = out.centre_count++;
  out.centre_sizes[c] = static_cast<std::uint8_t>(n);
  for (int i = 0; i < n; ++i) {
    out.centre_edges[c][static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>(loop[static_cast<std::size_t>(i)]);
    emit(CubeCase::kCentre + static_cast<int>(c), loop[static_cast<std::size_t>(i)],
         loop[static_cast<std::size_t>((i + 1) % n)]);
  }
}

// Triangulates corner mask `inside`, with `outside_joined` (one bit per face, all six) saying how
// each ambiguous face is decided.
CubeCase triangulate(unsigned inside, unsigned outside_joined) {
  std::array<int, 12> next;
  next.fill(-1);
  for (int face = 0; face < 6; ++face) {
    const auto corners = CubeCases::face_corners(face);
    auto in = [&](int k) { return (inside >> corners[static_cast<std::size_t>(k & 3)] & 1) != 0; };
    auto side_edge = [&](int k) {  // the face's edge from corner k to corner k + 1 (cyclically)
      return edge_between(corners[static_cast<std::size_t>(k & 3)],
                          corners[static_cast<std::size_t>((k + 1) & 3)]);
    };
    std::vector<int> crossing;  // face-side positions k whose edge crosses
    for (int k = 0; k < 4; ++k)
      if (in(k) != in(k + 1)) crossing.push_back(k);
    std::vector<std::pair<int, int>> segments;
    if (crossing.size() == 2) {
      segments.push_back({side_edge(crossing[0]), side_edge(crossing[1])});
    } else if (crossing.size() == 4) {
      // Cut off, one by one, the two corners that are not joined: the inside ones when the outside
      // corners connect across the face, else the outside ones. Corner k touches sides k-1 and k.
      const bool cut_inside = (outside_joined >> face & 1) != 0;
      for (int k = 0; k < 4; ++k)
        if (in(k) == cut_inside) segments.push_back({side_edge(k + 3), side_edge(k)});
    }
    for (const auto& [e0, e1] : segments) {
      const auto [from, to] = oriented_segment(face, e0, e1, inside);
      if (next[static_cast<std::size_t>(from)] != -1)
        throw std::logic_error("cube_cases: two segments leave one crossing");
      next[static_cast<std::size_t>(from)] = to;
    }
  }
  CubeCase result;
  std::array<bool, 12> used{};
  for (int start = 0; start < 12; ++start) {
    if (next[static_cast<std::size_t>(start)] == -1 || used[static_cast<std::size_t>(start)])
      continue;
    std::vector<int> loop;
    for (int e = start; !used[static_cast<std::size_t>(e)]; e = next[static_cast<std::size_t>(e)]) {
      used[static_cast<std::size_t>(e)] = true;
      loop.push_back(e);
      if (next[static_cast<std::size_t>(e)] == -1) throw std::logic_error("cube_cases: open loop");
    }
    if (loop.front() != start || next[static_cast<std::size_t>(loop.back())] != start ||
        loop.size() < 3)
      throw std::logic_error("cube_cases: loop does not close");
    triangulate_loop(loop, result);
  }
  return result;
}

}  // namespace

const std::array<CubeEdge, 12>& cube_edges() {
  static const std::array<CubeEdge, 12> edges = make_edges();
  return edges;
}

std::array<std::uint8_t, 4> CubeCases::face_corners(int face) {
  const int axis = face / 2, side = face % 2;
  const int lo = axis == 0 ? 1 : 0, hi = axis == 2 ? 1 : 2;
  const int base = side << axis;
  return {static_cast<std::uint8_t>(base), static_cast<std::uint8_t>(base | 1 << lo),
          static_cast<std::uint8_t>(base | 1 << lo | 1 << hi),
          static_cast<std::uint8_t>(base | 1 << hi)};
}

CubeCases::CubeCases() {
  std::size_t next_offset = 0;
  for (unsigned inside = 0; inside < 256; ++inside) {
    std::uint8_t ambiguous = 0;
    for (int face = 0; face < 6; ++face) {
      const auto c = face_corners(face);
      const unsigned b0 = inside >> c[0] & 1, b1 = inside >> c[1] & 1, b2 = inside >> c[2] & 1,
                     b3 = inside >> c[3] & 1;
      if (b0 == b2 && b1 == b3 && b0 != b1)
        ambiguous = static_cast<std::uint8_t>(ambiguous | 1 << face);
    }
    ambiguous_[inside] = ambiguous;
    for (std::size_t e = 0; e < 12; ++e) {
      const CubeEdge& edge = cube_edges()[e];
      if ((inside >> edge.from & 1) != (inside >> edge.to & 1)) {
        crossed_[inside] = static_cast<std::uint16_t>(crossed_[inside] | 1u << e);
        for (int a = 0; a < 3; ++a)
          if (a != edge.axis)
            corner_sums_[inside][static_cast<std::size_t>(a)] += edge.from >> a & 1;
      }
    }
    offset_[inside] = static_cast<std::uint16_t>(next_offset);
    std::vector<int> faces;
    for (int face = 0; face < 6; ++face)
      if (ambiguous >> face & 1) faces.push_back(face);
    for (unsigned joined = 0; joined < (1u << faces.size()); ++joined) {
      unsigned all = 0;
      for (std::size_t i = 0; i < faces.size(); ++i)
        if (joined >> i & 1) all |= 1u << faces[i];
      if (next_offset >= cases_.size()) throw std::logic_error("cube_cases: table too small");
      cases_[next_offset++] = triangulate(inside, all);
    }
  }
  offset_[256] = static_cast<std::uint16_t>(next_offset);
}

const CubeCases& CubeCases::get() {
  static const CubeCases table;
  return table;
}

}  // namespace voxfield::detail::mesh
