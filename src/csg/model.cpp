// voxfield CSG — the model as a function: the node kinds, the reference evaluation (the definitions
// of docs/csg.md applied recursively in double precision), materials, labels and bounds.
#include <algorithm>
#include <cmath>
#include <limits>

#include "csg/shapes.h"
#include "voxfield/csg.h"
#include "voxfield/limits.h"

namespace voxfield::csg {

const char* kind_name(NodeKind kind) {
  switch (kind) {
    case NodeKind::kSphere:
      return "sphere";
    case NodeKind::kBox:
      return "box";
    case NodeKind::kRoundedBox:
      return "rounded-box";
    case NodeKind::kCylinder:
      return "cylinder";
    case NodeKind::kCapsule:
      return "capsule";
    case NodeKind::kTorus:
      return "torus";
    case NodeKind::kCone:
      return "cone";
    case NodeKind::kPlane:
      return "plane";
    case NodeKind::kEllipsoid:
      return "ellipsoid";
    case NodeKind::kUnion:
      return "union";
    case NodeKind::kInter:
      return "inter";
    case NodeKind::kDiff:
      return "diff";
    case NodeKind::kSmoothUnion:
      return "smooth-union";
    case NodeKind::kSmoothInter:
      return "smooth-inter";
    case NodeKind::kSmoothDiff:
      return "smooth-diff";
    case NodeKind::kMove:
      return "move";
    case NodeKind::kRotate:
      return "rotate";
    case NodeKind::kScale:
      return "scale";
    case NodeKind::kRound:
      return "round";
    case NodeKind::kShell:
      return "shell";
    case NodeKind::kPaint:
      return "paint";
  }
  return "?";
}

bool is_shape(NodeKind kind) {
  return kind <= NodeKind::kEllipsoid;
}
bool is_boolean(NodeKind kind) {
  return kind >= NodeKind::kUnion && kind <= NodeKind::kSmoothDiff;
}

const char* label_name(Label label) {
  switch (label) {
    case Label::kExact:
      return "exact";
    case Label::kBound:
      return "bound";
    case Label::kApproximate:
      return "approximate";
  }
  return "?";
}

namespace {

// p in the child's frame of a transform node.
Vec3d into_child(const Node& n, Vec3d p) {
  switch (n.kind) {
    case NodeKind::kMove:
      return p - Vec3d{n.params[0], n.params[1], n.params[2]};
    case NodeKind::kRotate: {  // A(R^-1 p), and R^-1 = R^T
      const auto r = detail::rotation_matrix(n.params[0], {n.params[1], n.params[2], n.params[3]});
      return {r[0] * p.x + r[3] * p.y + r[6] * p.z, r[1] * p.x + r[4] * p.y + r[7] * p.z,
              r[2] * p.x + r[5] * p.y + r[8] * p.z};
    }
    case NodeKind::kScale:
      return p * (1.0 / n.params[0]);
    default:
      return p;
  }
}

double blend(NodeKind kind, double k, double a, double b) {
  switch (kind) {
    case NodeKind::kUnion:
      return std::min(a, b);
    case NodeKind::kInter:
      return std::max(a, b);
    case NodeKind::kDiff:
      return std::max(a, -b);
    case NodeKind::kSmoothUnion:
      return detail::smooth_min(a, b, k);
    case NodeKind::kSmoothInter:
      return detail::smooth_max(a, b, k);
    default:
      return detail::smooth_max(a, -b, k);  // kSmoothDiff
  }
}

// The value and material of a node at p; `material` is what the nearest enclosing paint gave.
double eval(const Model& m, int index, Vec3d p, std::uint8_t material, std::uint8_t* out_material) {
  const Node& n = m.nodes[static_cast<std::size_t>(index)];
  if (is_shape(n.kind)) {
    if (out_material) *out_material = material;
    return detail::shape_distance(n.kind, n.params.data(), p);
  }
  if (is_boolean(n.kind)) {
    const bool smooth = n.kind >= NodeKind::kSmoothUnion;
    const double k = smooth ? n.params[0] : 0;
    const bool union_like = n.kind == NodeKind::kUnion || n.kind == NodeKind::kSmoothUnion;
    std::uint8_t mat = material;
    double v = eval(m, n.children[0], p, material, out_material ? &mat : nullptr);
    for (std::size_t c = 1; c < n.children.size(); ++c) {
      std::uint8_t child_mat = material;
      const double w = eval(m, n.children[c], p, material, out_material ? &child_mat : nullptr);
      if (union_like && w < v) mat = child_mat;  // the winning branch; ties keep the first
      v = blend(n.kind, k, v, w);
    }
    if (out_material) *out_material = mat;
    return v;
  }
  const int child = n.children[0];
  switch (n.kind) {
    case NodeKind::kMove:
    case NodeKind::kRotate:
      return eval(m, child, into_child(n, p), material, out_material);
    case NodeKind::kScale:
      return n.params[0] * eval(m, child, into_child(n, p), material, out_material);
    case NodeKind::kRound:
      return eval(m, child, p, material, out_material) - n.params[0];
    case NodeKind::kShell:
      return std::abs(eval(m, child, p, material, out_material)) - n.params[0] / 2;
    default:  // kPaint: the innermost paint wins
      return eval(m, child, p, n.material, out_material);
  }
}

// The box of the points where the node's value is <= c (c >= 0), or nullopt when unbounded.
std::optional<Bounds> sublevel_box(const Model& m, int index, double c) {
  const Node& n = m.nodes[static_cast<std::size_t>(index)];
  const auto& s = n.params;
  auto centred = [c](double hx, double hy, double hz) {
    return Bounds{{-hx - c, -hy - c, -hz - c}, {hx + c, hy + c, hz + c}};
  };
  auto children = [&](double cc, bool intersect) -> std::optional<Bounds> {
    std::optional<Bounds> acc;
    bool any_unbounded = false;
    for (int child : n.children) {
      const auto b = sublevel_box(m, child, cc);
      if (!b) {
        any_unbounded = true;
        continue;
      }
      if (!acc) {
        acc = b;
      } else if (intersect) {
        acc->lo = {std::max(acc->lo.x, b->lo.x), std::max(acc->lo.y, b->lo.y),
                   std::max(acc->lo.z, b->lo.z)};
        acc->hi = {std::min(acc->hi.x, b->hi.x), std::min(acc->hi.y, b->hi.y),
                   std::min(acc->hi.z, b->hi.z)};
      } else {
        acc->lo = {std::min(acc->lo.x, b->lo.x), std::min(acc->lo.y, b->lo.y),
                   std::min(acc->lo.z, b->lo.z)};
        acc->hi = {std::max(acc->hi.x, b->hi.x), std::max(acc->hi.y, b->hi.y),
                   std::max(acc->hi.z, b->hi.z)};
      }
    }
    if (!intersect && any_unbounded) return std::nullopt;
    return acc;
  };
  switch (n.kind) {
    case NodeKind::kSphere:
      return centred(s[0], s[0], s[0]);
    case NodeKind::kBox:
    case NodeKind::kRoundedBox:
      return centred(s[0] / 2, s[1] / 2, s[2] / 2);
    case NodeKind::kCylinder:
    case NodeKind::kCone:
      return centred(s[0], s[0], s[1] / 2);
    case NodeKind::kCapsule:
      return centred(s[0], s[0], s[1] / 2 + s[0]);
    case NodeKind::kTorus:
      return centred(s[0] + s[1], s[0] + s[1], s[1]);
    case NodeKind::kPlane:
      return std::nullopt;
    case NodeKind::kEllipsoid: {
      // value <= c implies |p / r| <= 1 + c / min(r) (the value is at least (k0 - 1) min(r)).
      const double grow = 1 + c / std::min(s[0], std::min(s[1], s[2]));
      const Bounds b{{-s[0] * grow, -s[1] * grow, -s[2] * grow},
                     {s[0] * grow, s[1] * grow, s[2] * grow}};
      return b;
    }
    case NodeKind::kUnion:
      return children(c, false);
    case NodeKind::kInter:
    case NodeKind::kSmoothInter:
      return children(c, true);  // smooth max >= max
    case NodeKind::kDiff:
    case NodeKind::kSmoothDiff:
      return sublevel_box(m, n.children[0], c);
    case NodeKind::kSmoothUnion:
      return children(c + s[0] / 4, false);  // smooth min >= min - k/4
    case NodeKind::kRound:
      return sublevel_box(m, n.children[0], c + s[0]);
    case NodeKind::kShell:
      return sublevel_box(m, n.children[0], c + s[0] / 2);
    case NodeKind::kPaint:
      return sublevel_box(m, n.children[0], c);
    case NodeKind::kScale: {
      auto b = sublevel_box(m, n.children[0], c / s[0]);
      if (b) b = Bounds{b->lo * s[0], b->hi * s[0]};
      return b;
    }
    case NodeKind::kMove: {
      auto b = sublevel_box(m, n.children[0], c);
      const Vec3d t{s[0], s[1], s[2]};
      if (b) b = Bounds{b->lo + t, b->hi + t};
      return b;
    }
    case NodeKind::kRotate: {
      const auto b = sublevel_box(m, n.children[0], c);
      if (!b || b->empty()) return b;
      const auto r = detail::rotation_matrix(s[0], {s[1], s[2], s[3]});
      Bounds out{Vec3d{1, 1, 1} * std::numeric_limits<double>::infinity(),
                 Vec3d{1, 1, 1} * -std::numeric_limits<double>::infinity()};
      for (int corner = 0; corner < 8; ++corner) {
        const Vec3d q{corner & 1 ? b->hi.x : b->lo.x, corner & 2 ? b->hi.y : b->lo.y,
                      corner & 4 ? b->hi.z : b->lo.z};
        for (int a = 0; a < 3; ++a) {
          const double v = r[a * 3] * q.x + r[a * 3 + 1] * q.y + r[a * 3 + 2] * q.z;
          out.lo[a] = std::min(out.lo[a], v);
          out.hi[a] = std::max(out.hi[a], v);
        }
      }
      return out;
    }
  }
  return std::nullopt;
}

struct Counts {
  std::int64_t nodes = 0, shapes = 0;
};

}  // namespace

double evaluate_node(const Model& model, int node, Vec3d p) {
  return eval(model, node, p, kDefaultMaterial, nullptr);
}

double evaluate(const Model& model, Vec3d p) {
  return evaluate_node(model, model.root, p);
}

std::uint8_t material_at(const Model& model, Vec3d p) {
  std::uint8_t m = kDefaultMaterial;
  (void)eval(model, model.root, p, kDefaultMaterial, &m);
  return m;
}

Label label_of(const Model& model, int index) {
  const Node& n = model.nodes[static_cast<std::size_t>(index)];
  if (is_shape(n.kind)) return n.kind == NodeKind::kEllipsoid ? Label::kApproximate : Label::kExact;
  Label worst = Label::kExact;
  for (int child : n.children) worst = std::max(worst, label_of(model, child));
  if (worst == Label::kApproximate) return worst;
  // Two or more operands: a union is exact only outside, an intersection or difference only
  // inside, a smooth blend nowhere; all stay 1-Lipschitz, hence bounds.
  if (is_boolean(n.kind) && (n.children.size() > 1 || n.kind >= NodeKind::kSmoothUnion))
    return Label::kBound;
  return worst;  // transforms, rounding, shells and paint keep their operand's label
}

std::optional<Bounds> model_bounds(const Model& model) {
  return sublevel_box(model, model.root, 0);
}

Bounds box_or_bounds(const Model& model, const std::optional<Bounds>& box) {
  if (box) {
    if (box->empty() ||
        !std::isfinite(box->lo.x + box->lo.y + box->lo.z + box->hi.x + box->hi.y + box->hi.z))
      throw InvalidArgument(model.name + ": the box must be finite with lo <= hi on every axis");
    return *box;
  }
  const auto bounds = model_bounds(model);
  if (!bounds)
    throw InvalidArgument(
        model.name +
        ": the model is unbounded (it has a plane or a difference from one); give a box");
  return *bounds;
}

ModelInfo model_info(const Model& model) {
  // Counts over the tree as written out, memoised per stored node (a DAG can expand
  // exponentially: the counts saturate rather than wrap).
  std::vector<Counts> counts(model.nodes.size());
  for (std::size_t i = 0; i < model.nodes.size(); ++i) {
    const Node& n = model.nodes[i];
    Counts c{1, is_shape(n.kind) ? 1 : 0};
    for (int child : n.children) {
      const Counts& k = counts[static_cast<std::size_t>(child)];
      c.nodes = static_cast<std::int64_t>(
          add_sat(static_cast<std::uint64_t>(c.nodes), static_cast<std::uint64_t>(k.nodes)));
      c.shapes = static_cast<std::int64_t>(
          add_sat(static_cast<std::uint64_t>(c.shapes), static_cast<std::uint64_t>(k.shapes)));
    }
    c.nodes = std::min<std::int64_t>(c.nodes, std::numeric_limits<std::int64_t>::max() / 2);
    c.shapes = std::min<std::int64_t>(c.shapes, std::numeric_limits<std::int64_t>::max() / 2);
    counts[i] = c;
  }
  ModelInfo info;
  const Counts& root = counts[static_cast<std::size_t>(model.root)];
  info.nodes = root.nodes;
  info.shapes = root.shapes;
  info.unique_nodes = static_cast<std::int64_t>(model.nodes.size());
  info.label = label_of(model, model.root);
  info.bounds = model_bounds(model);
  return info;
}

}  // namespace voxfield::csg
