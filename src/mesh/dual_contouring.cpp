// voxfield — dual contouring's vertex placement.
//
// T. Ju, F. Losasso, S. Schaefer & J. Warren, "Dual Contouring of Hermite Data", SIGGRAPH 2002:
// each crossing on a cell's edges carries the field's normal there (Hermite data); the cell's
// vertex minimises the quadratic error function E(x) = sum_i (n_i . (x - p_i))^2, the squared
// distances to the crossings' tangent planes, so that where planes meet at an edge or a corner of
// the surface the vertex lands on it: sharp features stay sharp. Solved as S. Schaefer & J. Warren
// advise ("Dual Contouring: The Secret Sauce", 2002): relative to the mass point m (the mean of
// the crossings), by the pseudo-inverse of AᵀA from its eigen-decomposition (Jacobi rotations),
// with eigenvalues below a fraction of the largest truncated, so that flat and creased regions,
// whose systems are rank-deficient, move towards m only along the directions the planes fix.
// The vertex is kept inside its cell (clamped), which keeps the quads from folding over.
//
// Normals at crossings blend one-sided gradients at the edge's two samples (Block::
// one_sided_gradient: taken from the smoother side, so a crease does not smear the planes of the
// faces meeting there); positions and normals are in world units, so anisotropic spacing is exact.
// With MeshOptions::gradient (an analytic model's) the normals at crossings are that gradient. For
// voxel worlds the Hermite data is exact too: each crossing lies on the face between a solid and
// an air voxel, with that face's normal, so the mesh is the voxels' cubes, corners and all.
#include <cmath>

#include "chunked_mesh.h"
#include "cube_cases.h"

namespace voxfield::detail::mesh {

namespace {

using Mat3 = std::array<std::array<double, 3>, 3>;

// Eigen-decomposition of a symmetric 3 x 3 matrix by cyclic Jacobi rotations: a = V diag(w) Vᵀ.
void symmetric_eigen(Mat3 a, std::array<double, 3>& w, Mat3& v) {
  v = {{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int sweep = 0; sweep < 16; ++sweep) {
    const double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    if (off < 1e-24) break;
    for (int p = 0; p < 2; ++p)
      for (int q = p + 1; q < 3; ++q) {
        if (std::abs(a[p][q]) < 1e-300) continue;
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t = (theta >= 0 ? 1 : -1) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // a = Jᵀ a J, v = v J
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 3; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  w = {a[0][0], a[1][1], a[2][2]};
}

// Eigenvalues of AᵀA below this fraction of the largest are treated as zero (the Secret Sauce's
// truncation; with unit normals the largest is at most the number of crossings).
constexpr double kTruncation = 0.01;

}  // namespace

std::array<double, 3> dual_contouring_vertex(const Block& block, const Lattice& lattice, Vec3i cell,
                                             const double* v) {
  const auto& h = lattice.spacing;
  std::array<std::array<double, 3>, 12> points, normals;
  int n = 0;
  std::array<double, 3> mass{0, 0, 0};
  for (const CubeEdge& e : cube_edges()) {
    const double s0 = v[e.from], s1 = v[e.to];
    if ((s0 < 0) == (s1 < 0)) continue;
    Vec3i p0 = cell, p1 = cell;
    for (int a = 0; a < 3; ++a) {
      p0[a] += e.from >> a & 1;
      p1[a] += e.to >> a & 1;
    }
    const double t = lattice.crossing(p0, e.axis, s0, s1);
    std::array<double, 3> g{};
    if (lattice.voxel_faces) {
      g[e.axis] = s0 < 0 ? 1 : -1;  // from the solid voxel towards the air
    } else if (lattice.gradient) {  // exact Hermite data from the caller's gradient
      std::array<double, 3> at{static_cast<double>(p0.x), static_cast<double>(p0.y),
                               static_cast<double>(p0.z)};
      at[static_cast<std::size_t>(e.axis)] += t;
      g = lattice.exact_normal(lattice_position(lattice, at));
    } else {
      const auto g0 = block.one_sided_gradient(p0.x, p0.y, p0.z),
                 g1 = block.one_sided_gradient(p1.x, p1.y, p1.z);
      for (std::size_t a = 0; a < 3; ++a) g[a] = g0[a] + t * (g1[a] - g0[a]);
    }
    double length = 0;
    for (std::size_t a = 0; a < 3; ++a) length += g[a] * g[a];
    length = std::sqrt(length);
    for (std::size_t a = 0; a < 3; ++a) {
      // The crossing in world units relative to the cell's lowest corner.
      const double local = a == e.axis ? t : (e.from >> a & 1);
      points[static_cast<std::size_t>(n)][a] = local * h[a];
      normals[static_cast<std::size_t>(n)][a] = length > 0 ? g[a] / length : 0;
      mass[a] += local * h[a];
    }
    ++n;
  }
  for (double& m : mass) m /= n;
  // AᵀA and Aᵀ(b - A m), with the rows n_i and b_i = n_i . p_i.
  Mat3 ata{};
  std::array<double, 3> atb{0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const auto& ni = normals[static_cast<std::size_t>(i)];
    const auto& pi = points[static_cast<std::size_t>(i)];
    const double r =
        ni[0] * (pi[0] - mass[0]) + ni[1] * (pi[1] - mass[1]) + ni[2] * (pi[2] - mass[2]);
    for (std::size_t a = 0; a < 3; ++a) {
      atb[a] += ni[a] * r;
      for (std::size_t b = 0; b < 3; ++b) ata[a][b] += ni[a] * ni[b];
    }
  }
  std::array<double, 3> w;
  Mat3 vec;
  symmetric_eigen(ata, w, vec);
  const double largest = std::max({w[0], w[1], w[2]});
  std::array<double, 3> x = mass;
  if (largest > 0)
    for (std::size_t k = 0; k < 3; ++k) {
      if (w[k] < kTruncation * largest) continue;
      const double along = (vec[0][k] * atb[0] + vec[1][k] * atb[1] + vec[2][k] * atb[2]) / w[k];
      for (std::size_t a = 0; a < 3; ++a) x[a] += vec[a][k] * along;
    }
  std::array<double, 3> local;
  for (std::size_t a = 0; a < 3; ++a) local[a] = std::clamp(x[a] / h[a], 0.0, 1.0);
  return local;
}

}  // namespace voxfield::detail::mesh
