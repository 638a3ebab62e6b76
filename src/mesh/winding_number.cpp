// The generalized winding number of a triangle soup (Jacobson, Kavan & Sorkine-Hornung 2013,
// "Robust inside-outside segmentation using generalized winding numbers"), evaluated with the
// hierarchy of Barill, Dickson, Schmidt, Levin & Jacobson 2018 ("Fast winding numbers for soups
// and clouds"), section 3.
//
// Each triangle contributes its signed solid angle seen from the query point over 4π (Van Oosterom
// & Strackee 1983's closed form). A bounding-volume hierarchy groups the triangles; a cluster far
// from the point — farther than `accuracy` times its radius from its centre — is replaced by the
// first two terms of its far-field expansion about the area-weighted centroid (the paper's
// equation 15 to second order): a dipole whose moment is the sum of the triangles' area-weighted
// normals, and a quadrupole from each triangle's normal times its centroid's offset — exact for
// the linear term, since a triangle's first moment is its area times its centroid. The error then
// falls as (radius / distance)^3, so points near the surface still get the exact sum from the
// triangles around them while a far point costs a handful of clusters.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>

#include "mesh_triangles.h"
#include "voxfield/error.h"
#include "voxfield/mesh_voxelize.h"

namespace voxfield {
namespace {

using detail::triangles::cross;
using detail::triangles::dot;
using detail::triangles::sub;
using detail::triangles::V3;
constexpr double kInvFourPi = 0.25 / 3.14159265358979323846;
constexpr int kLeafTriangles = 8;
constexpr double kRefineMargin = 0.25;

double length3(const V3& a) {
  return std::sqrt(dot(a, a));
}

// The solid angle of triangle abc seen from the origin (a, b, c relative to the query point),
// positive when the triangle turns counter-clockwise around the direction away from the point.
double solid_angle(const V3& a, const V3& b, const V3& c) {
  const double la = length3(a), lb = length3(b), lc = length3(c);
  const double det = dot(a, cross(b, c));
  const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0 * std::atan2(det, den);
}

}  // namespace

struct WindingNumber::Tree {
  struct Node {
    V3 centre{};                         // area-weighted centroid of the cluster's triangles
    V3 moment{};                         // sum of area-weighted normals (half the cross products)
    std::array<double, 9> quadrupole{};  // sum of area-weighted normal x (centroid - centre)
    double radius = 0;                   // farthest vertex of the cluster from the centre
    std::uint32_t begin = 0, end = 0;    // the cluster's triangles in `corners`' order
    std::int32_t left = -1, right = -1;
  };
  std::vector<Node> nodes;
  std::vector<std::array<V3, 3>> corners;  // triangles in tree order, corners copied for locality
  double accuracy = 2;

  double leaf_sum(const Node& n, const V3& q) const {
    double sum = 0;
    for (std::uint32_t t = n.begin; t < n.end; ++t) {
      const auto& c = corners[t];
      sum += solid_angle(sub(c[0], q), sub(c[1], q), sub(c[2], q));
    }
    return sum * kInvFourPi;
  }
};

WindingNumber::WindingNumber(const TriangleMesh& mesh, double accuracy) {
  if (!(accuracy >= 1) || !std::isfinite(accuracy))
    throw InvalidArgument("WindingNumber: the accuracy must be >= 1 (Barill et al. use 2)");
  mesh.validate();
  auto tree = std::make_unique<Tree>();
  tree->accuracy = accuracy;
  const auto& positions = mesh.positions;
  const auto& triangles = mesh.triangles;
  const std::size_t n = triangles.size();
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::vector<V3> centroid(n);
  for (std::size_t t = 0; t < n; ++t) {
    const auto& tri = triangles[t];
    for (int k = 0; k < 3; ++k)
      centroid[t][k] = (positions[tri[0]][k] + positions[tri[1]][k] + positions[tri[2]][k]) / 3;
  }
  // Top-down median splits on the centroids' longest axis; an explicit stack (a degenerate soup of
  // a million coincident triangles must not recurse a million deep: median splits keep the depth
  // at log2(n) whatever the geometry).
  struct Pending {
    std::uint32_t begin, end;
    std::int32_t node;
  };
  tree->nodes.reserve(n / kLeafTriangles * 2 + 1);
  tree->nodes.push_back({});
  std::vector<Pending> stack{{0, static_cast<std::uint32_t>(n), 0}};
  while (!stack.empty()) {
    const Pending p = stack.back();
    stack.pop_back();
    tree->nodes[p.node].begin = p.begin;
    tree->nodes[p.node].end = p.end;
    if (p.end - p.begin <= kLeafTriangles) continue;
    V3 lo{HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi{-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    for (std::uint32_t i = p.begin; i < p.end; ++i)
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], centroid[order[i]][k]);
        hi[k] = std::max(hi[k], centroid[order[i]][k]);
      }
    int axis = 0;
    for (int k = 1; k < 3; ++k)
      if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
    const std::uint32_t mid = p.begin + (p.end - p.begin) / 2;
    std::nth_element(
        order.begin() + p.begin, order.begin() + mid, order.begin() + p.end,
        [&](std::uint32_t a, std::uint32_t b) { return centroid[a][axis] < centroid[b][axis]; });
    const auto left = static_cast<std::int32_t>(tree->nodes.size());
    tree->nodes.push_back({});
    tree->nodes.push_back({});
    tree->nodes[p.node].left = left;
    tree->nodes[p.node].right = left + 1;
    stack.push_back({p.begin, mid, left});
    stack.push_back({mid, p.end, left + 1});
  }
  tree->corners.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& tri = triangles[order[i]];
    tree->corners[i] = {positions[tri[0]], positions[tri[1]], positions[tri[2]]};
  }
  // Moments bottom-up: children are always stored after their parent, so a reverse sweep sees
  // both children of a node before the node itself.
  for (std::size_t i = tree->nodes.size(); i-- > 0;) {
    Tree::Node& node = tree->nodes[i];
    double area_sum = 0;
    V3 weighted{0, 0, 0}, moment{0, 0, 0};
    for (std::uint32_t t = node.begin; t < node.end; ++t) {
      const auto& c = tree->corners[t];
      const V3 half_normal = [&] {
        V3 v = cross(sub(c[1], c[0]), sub(c[2], c[0]));
        return V3{0.5 * v[0], 0.5 * v[1], 0.5 * v[2]};
      }();
      const double area = length3(half_normal);
      for (int k = 0; k < 3; ++k) {
        moment[k] += half_normal[k];
        weighted[k] += area * (c[0][k] + c[1][k] + c[2][k]) / 3;
      }
      area_sum += area;
    }
    if (area_sum > 0) {
      for (int k = 0; k < 3; ++k) node.centre[k] = weighted[k] / area_sum;
    } else if (node.end > node.begin) {
      node.centre = tree->corners[node.begin][0];  // degenerate triangles only: no dipole moment
    }
    node.moment = moment;
    for (std::uint32_t t = node.begin; t < node.end; ++t) {
      const auto& c = tree->corners[t];
      const V3 n = cross(sub(c[1], c[0]), sub(c[2], c[0]));
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          node.quadrupole[3 * i + j] +=
              0.5 * n[i] * ((c[0][j] + c[1][j] + c[2][j]) / 3 - node.centre[j]);
    }
    double r2 = 0;
    for (std::uint32_t t = node.begin; t < node.end; ++t)
      for (const V3& v : tree->corners[t]) {
        const V3 d = sub(v, node.centre);
        r2 = std::max(r2, dot(d, d));
      }
    node.radius = std::sqrt(r2);
  }
  tree_ = tree.release();
}

WindingNumber::~WindingNumber() {
  delete tree_;
}
WindingNumber::WindingNumber(WindingNumber&& o) noexcept : tree_(o.tree_) {
  o.tree_ = nullptr;
}
WindingNumber& WindingNumber::operator=(WindingNumber&& o) noexcept {
  if (this != &o) {
    delete tree_;
    tree_ = o.tree_;
    o.tree_ = nullptr;
  }
  return *this;
}

double WindingNumber::evaluate(const V3& q, double accuracy) const {
  if (tree_->corners.empty()) return 0;
  double sum = 0;
  std::int32_t stack[64];  // median splits: the depth is log2(n / 8) + 1, far below 64
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Tree::Node& n = tree_->nodes[stack[--top]];
    const V3 d = sub(n.centre, q);
    const double dist2 = dot(d, d);
    const double reach = accuracy * n.radius;
    if (dist2 > reach * reach) {
      // With x = centre - q and r = |x|: the dipole x . moment / r^3, and the quadrupole
      // trace(Q) / r^3 - 3 x^T Q x / r^5 (the gradient of the dipole's kernel along each
      // triangle's offset), over 4π.
      const double r3 = dist2 * std::sqrt(dist2);
      const auto& m = n.quadrupole;
      double xqx = 0;
      for (int i = 0; i < 3; ++i)
        xqx += d[i] * (m[3 * i] * d[0] + m[3 * i + 1] * d[1] + m[3 * i + 2] * d[2]);
      sum +=
          kInvFourPi * (dot(d, n.moment) / r3 + (m[0] + m[4] + m[8]) / r3 - 3 * xqx / (r3 * dist2));
    } else if (n.left < 0) {
      sum += tree_->leaf_sum(n, q);
    } else {
      stack[top++] = n.left;
      stack[top++] = n.right;
    }
  }
  return sum;
}

double WindingNumber::operator()(const V3& q) const {
  return evaluate(q, tree_->accuracy);
}

bool WindingNumber::inside(const V3& q) const {
  const double fast = evaluate(q, tree_->accuracy);
  // The fast value's error stays below 0.07 of a turn in every test (docs/mesh_input.md): only a
  // value that close to the threshold is asked again, with clusters four times farther away.
  if (std::abs(fast - 0.5) >= kRefineMargin) return fast >= 0.5;
  return evaluate(q, 4 * tree_->accuracy) >= 0.5;
}

double WindingNumber::exact(const V3& q) const {
  double sum = 0;
  for (const auto& c : tree_->corners) sum += solid_angle(sub(c[0], q), sub(c[1], q), sub(c[2], q));
  return sum * kInvFourPi;
}

}  // namespace voxfield
