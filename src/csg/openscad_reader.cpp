// voxfield CSG — importing OpenSCAD's flattened CSG tree (the .csg file `openscad -o model.csg`
// writes): group, union, difference, intersection, render, multmatrix, color, cube, sphere and
// cylinder. The tree is translated into the model language (docs/csg.md) and parsed as such, so
// imported models get every check and label native ones get.
//
// multmatrix transforms are pushed down to the shapes. Each shape's matrix is split into a
// rotation and a symmetric stretch (polar decomposition): rigid motions and scales along the
// shape's own axes become native shapes (a scaled cube a box, a stretched sphere an ellipsoid, a
// frustum a cone cut by a slab); a stretched sphere in any other direction an ellipsoid along the
// stretch's eigenvectors. A sheared cube, and with `facets` every shape, becomes the polytope
// OpenSCAD itself meshes: the intersection of its faces' half-spaces, with OpenSCAD's fragment
// count (get_fragments_from_r) and sphere rings. The format's numbers carry six significant
// digits, so rotations are compared with a tolerance.
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <sstream>

#include "csg/datum.h"
#include "csg/linalg.h"
#include "csg/openscad_parser.h"
#include "voxfield/csg.h"
#include "voxfield/limits.h"

namespace voxfield::csg {
namespace {

using detail::Mat3;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTolerance = 1e-4;  // relative: the six digits of the format, with room
constexpr int kMaxFragments = 1024;
// Planes a translation may hold in all (a --facets sphere of n fragments has about n^2/2): the
// model language's own limit on nodes.
constexpr std::int64_t kMaxPlanes = 600000;
// What a plane costs on its way to a model — its line of the translation, then its parsed node and
// shape — counted against the memory limit so that a short file cannot ask for more than it allows
// (measured: 438 MB of peak RSS for the 450 000 planes of sphere($fn = 950) imported and parsed).
constexpr std::uint64_t kBytesPerPlane = 1024;

using openscad::Parser;
using openscad::Statement;
using openscad::Value;

// An affine map p -> m p + t.
struct Xform {
  Mat3 m{1, 0, 0, 0, 1, 0, 0, 0, 1};
  Vec3d t;
};

std::string num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, std::abs(v) < 1e-300 ? 0.0 : v);
  return std::string(buf, r.ptr);
}

class Translator {
 public:
  Translator(const Parser& parser, const OpenScadOptions& o) : parser_(parser), o_(o) {}

  // The model-language expression of a statement, or empty when it makes no geometry.
  std::string convert(const Statement& s, const Xform& x, const std::string& colour) {
    const std::string& n = s.name;
    if (n == "group" || n == "union" || n == "render" || n == "root")
      return combine("union", s, x, colour);
    if (n == "difference") return combine("diff", s, x, colour);
    if (n == "intersection") return combine("inter", s, x, colour);
    if (n == "multmatrix") return combine("union", s, compose(x, matrix(s)), colour);
    if (n == "color") return combine("union", s, x, paint(s, colour));
    if (n == "cube") return shape(s, x, colour, cube(s));
    if (n == "sphere") return shape(s, x, colour, sphere(s));
    if (n == "cylinder") return shape(s, x, colour, cylinder(s));
    parser_.fail(s.pos, n + "() is not supported by voxfield's OpenSCAD import (supported: group, "
                            "union, difference, "
                            "intersection, render, multmatrix, color, cube, sphere, cylinder)");
  }

 private:
  // A shape in its own frame: the native form (empty when it needs the polytope) and the polytope.
  struct Shape {
    enum class Kind { kBox, kSphere, kCylinder } kind = Kind::kBox;
    Vec3d size;    // box: full extents; sphere: r in x; cylinder: (r1, r2, h)
    Vec3d centre;  // where the shape's centre sits in its frame (cube and cylinder not centred)
    int fragments = 0;
    bool empty = false;
  };

  std::string combine(const char* op, const Statement& s, const Xform& x,
                      const std::string& colour) {
    std::vector<std::string> parts;
    std::vector<const Statement*>
        kept;  // background (%) and disabled (*) subtrees are not in the model
    for (const Statement& c : s.children)
      if (c.modifier != '%' && c.modifier != '*') kept.push_back(&c);
    for (std::size_t i = 0; i < kept.size(); ++i) {
      std::string e = convert(*kept[i], x, colour);
      if (e.empty()) {
        // The first operand of a difference, or any of an intersection, being empty empties it.
        if ((std::string_view(op) == "diff" && i == 0) || std::string_view(op) == "inter")
          return {};
        continue;
      }
      parts.push_back(std::move(e));
    }
    if (parts.empty()) return {};
    if (parts.size() == 1) return parts[0];
    std::string out = std::string("(") + op;
    for (const std::string& p : parts) out += "\n " + p;
    return out + ")";
  }

  const Value* arg(const Statement& s, const std::string& key, std::size_t position) const {
    std::size_t positional = 0;
    for (const auto& [k, v] : s.args) {
      if (k == key) return &v;
      if (k.empty() && positional++ == position) return &v;
    }
    return nullptr;
  }
  double number(const Statement& s, const std::string& key, double fallback) const {
    const Value* v = arg(s, key, 99);
    if (!v || v->type == Value::Type::kUndef) return fallback;
    if (v->type != Value::Type::kNumber)
      parser_.fail(s.pos, s.name + "(): " + key + " must be a number");
    return v->number;
  }
  bool flag(const Statement& s, const std::string& key) const {
    const Value* v = arg(s, key, 99);
    return v && v->type == Value::Type::kBool && v->boolean;
  }

  Xform matrix(const Statement& s) const {
    const Value* v = arg(s, "m", 0);
    Xform out;
    if (!v || v->type != Value::Type::kVector || v->items.size() < 3)
      parser_.fail(s.pos, "multmatrix() needs a 4 x 4 (or 3 x 4) matrix");
    Mat3& m = out.m;
    for (int r = 0; r < 3; ++r) {
      const Value& row = v->items[static_cast<std::size_t>(r)];
      if (row.type != Value::Type::kVector || row.items.size() < 4)
        parser_.fail(s.pos, "multmatrix(): each row needs four numbers");
      for (int c = 0; c < 4; ++c)
        if (row.items[static_cast<std::size_t>(c)].type != Value::Type::kNumber)
          parser_.fail(s.pos, "multmatrix(): each row needs four numbers");
      for (int c = 0; c < 3; ++c)
        m[static_cast<std::size_t>(r * 3 + c)] = row.items[static_cast<std::size_t>(c)].number;
      out.t[r] = row.items[3].number;
    }
    if (v->items.size() >= 4) {  // the last row must be (0, 0, 0, 1): no projection
      const Value& last = v->items[3];
      const double want[4] = {0, 0, 0, 1};
      for (int c = 0;
           c < 4 && last.type == Value::Type::kVector && c < static_cast<int>(last.items.size());
           ++c)
        if (std::abs(last.items[static_cast<std::size_t>(c)].number - want[c]) > kTolerance)
          parser_.fail(s.pos, "multmatrix(): a projective last row is not supported");
    }
    return out;
  }
  static Xform compose(const Xform& outer, const Xform& inner) {
    return {detail::mul(outer.m, inner.m), detail::apply(outer.m, inner.t) + outer.t};
  }

  std::string paint(const Statement& s, const std::string& colour) const {
    const Value* v = arg(s, "c", 0);
    if (v && v->type == Value::Type::kString && v->text.size() == 7 && v->text[0] == '#')
      return "\"" + v->text + "\"";
    if (!v || v->type != Value::Type::kVector || v->items.size() < 3)
      return colour;  // named colours: keep the outer
    char buf[8];
    int rgb[3];
    for (int i = 0; i < 3; ++i) {
      const Value& c = v->items[static_cast<std::size_t>(i)];
      rgb[i] = c.type == Value::Type::kNumber
                   ? static_cast<int>(std::lround(std::clamp(c.number, 0.0, 1.0) * 255))
                   : 0;
    }
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
    return std::string("\"") + buf + "\"";
  }

  // OpenSCAD's get_fragments_from_r.
  // OpenSCAD's get_fragments_from_r, in doubles (huge or infinite counts are refused before any
  // cast to int).
  static double fragments(double r, double fn, double fs, double fa) {
    if (r < 0.00000095367431640625) return 3;
    if (fn > 0) return fn >= 3 ? std::floor(fn) : 3;
    return std::ceil(std::max(std::min(360.0 / fa, r * 2 * kPi / fs), 5.0));
  }
  int fragments_of(const Statement& s, double r) const {
    const double f = fragments(r, number(s, "$fn", 0), number(s, "$fs", 2), number(s, "$fa", 12));
    if (!(f <= kMaxFragments))
      parser_.fail(s.pos, s.name + "(): more than " + std::to_string(kMaxFragments) + " fragments");
    return static_cast<int>(f);
  }

  Shape cube(const Statement& s) const {
    Shape out;
    const Value* v = arg(s, "size", 0);
    Vec3d size{1, 1, 1};
    if (v && v->type == Value::Type::kNumber) size = Vec3d{1, 1, 1} * v->number;
    if (v && v->type == Value::Type::kVector && v->items.size() == 3)
      for (int a = 0; a < 3; ++a) size[a] = v->items[static_cast<std::size_t>(a)].number;
    out.size = size;
    out.empty = !(size.x > 0 && size.y > 0 && size.z > 0);
    out.centre = flag(s, "center") ? Vec3d{} : size * 0.5;
    return out;
  }
  Shape sphere(const Statement& s) const {
    Shape out;
    out.kind = Shape::Kind::kSphere;
    const double r = number(s, "r", 1);
    out.size = {r, r, r};
    out.empty = !(r > 0);
    if (!out.empty) out.fragments = fragments_of(s, r);
    return out;
  }
  Shape cylinder(const Statement& s) const {
    Shape out;
    out.kind = Shape::Kind::kCylinder;
    const double r = number(s, "r", 1), h = number(s, "h", 1);
    const double r1 = number(s, "r1", r), r2 = number(s, "r2", r);
    out.size = {r1, r2, h};
    out.empty = !(h > 0) || r1 < 0 || r2 < 0 || (r1 == 0 && r2 == 0);
    out.centre = flag(s, "center") ? Vec3d{} : Vec3d{0, 0, h / 2};
    if (!out.empty) out.fragments = fragments_of(s, std::max(r1, r2));
    return out;
  }

  std::string shape(const Statement& s, const Xform& x, const std::string& colour,
                    const Shape& sh) {
    if (sh.empty) return {};
    const Vec3d t = detail::apply(x.m, sh.centre) + x.t;
    Mat3 m = x.m;
    const double d = detail::det(m);
    double scale_max = 0;
    for (double v : m) scale_max = std::max(scale_max, std::abs(v));
    if (!(std::abs(d) > 1e-12 * scale_max * scale_max * scale_max))
      parser_.fail(s.pos, s.name + "(): its transform flattens it (a singular matrix)");
    // A mirror: every supported shape is symmetric across x = 0 in its frame.
    if (d < 0) m = detail::mul(m, Mat3{-1, 0, 0, 0, 1, 0, 0, 0, 1});
    std::string e;
    if (o_.facets && sh.kind != Shape::Kind::kBox) {
      e = polytope(s, sh, m, t);
    } else {
      Mat3 r, st;
      detail::polar(m, r, st);
      const double big = std::max({std::abs(st[0]), std::abs(st[4]), std::abs(st[8])});
      const bool diagonal = std::abs(st[1]) + std::abs(st[2]) + std::abs(st[5]) <= kTolerance * big;
      const Vec3d k{st[0], st[4], st[8]};
      if (sh.kind == Shape::Kind::kBox) {
        e = diagonal ? placed("(box " + num(sh.size.x * k.x) + " " + num(sh.size.y * k.y) + " " +
                                  num(sh.size.z * k.z) + ")",
                              r, t)
                     : polytope(s, sh, m, t);
      } else if (sh.kind == Shape::Kind::kSphere) {
        if (diagonal) {
          const bool uniform =
              std::abs(k.x - k.y) <= kTolerance * big && std::abs(k.x - k.z) <= kTolerance * big;
          e = placed(uniform ? "(sphere " + num(sh.size.x * (k.x + k.y + k.z) / 3) + ")"
                             : "(ellipsoid " + num(sh.size.x * k.x) + " " + num(sh.size.x * k.y) +
                                   " " + num(sh.size.x * k.z) + ")",
                     r, t);
        } else {
          Mat3 v;
          Vec3d w;
          detail::eigen_symmetric(st, v, w);
          e = placed("(ellipsoid " + num(sh.size.x * w.x) + " " + num(sh.size.x * w.y) + " " +
                         num(sh.size.x * w.z) + ")",
                     detail::mul(r, v), t);
        }
      } else {
        if (!diagonal || std::abs(k.x - k.y) > kTolerance * big)
          parser_.fail(
              s.pos,
              "cylinder(): stretched unequally across its axis (an elliptic cylinder); import with "
              "facets to mesh it as OpenSCAD does");
        e = placed(frustum(sh.size.x * k.x, sh.size.y * k.x, sh.size.z * k.z), r, t);
      }
    }
    return colour.empty() ? e : "(paint " + colour + " " + e + ")";
  }

  // A cylinder or frustum of bottom radius r1, top radius r2 and height h, centred.
  static std::string frustum(double r1, double r2, double h) {
    if (std::abs(r1 - r2) <= kTolerance * std::max(r1, r2))
      return "(cylinder " + num((r1 + r2) / 2) + " " + num(h) + ")";
    const bool flip = r2 > r1;
    const double base = flip ? r2 : r1, top = flip ? r1 : r2;
    std::string cone;
    if (top <= 0) {
      cone = "(cone " + num(base) + " " + num(h) + ")";
    } else {  // the whole cone up to its apex, cut by the slab of the frustum
      const double full = h * base / (base - top);
      cone = "(inter (move 0 0 " + num(full / 2 - h / 2) + " (cone " + num(base) + " " + num(full) +
             ")) (box " + num(2.02 * base) + " " + num(2.02 * base) + " " + num(h) + "))";
    }
    return flip ? "(rotate-x 180 " + cone + ")" : cone;
  }

  // An expression rotated by r and moved to t.
  static std::string placed(const std::string& e, const Mat3& r, Vec3d t) {
    double deg = 0;
    Vec3d axis;
    detail::axis_angle(r, deg, axis);
    std::string out = e;
    if (std::abs(deg) > 1e-9)
      out = "(rotate " + num(deg) + " " + num(axis.x) + " " + num(axis.y) + " " + num(axis.z) +
            " " + out + ")";
    if (t.length() > 0)
      out = "(move " + num(t.x) + " " + num(t.y) + " " + num(t.z) + " " + out + ")";
    return out;
  }

  // The convex polytope OpenSCAD meshes for the shape, as the intersection of its faces'
  // half-spaces, its vertices mapped by m and t.
  std::string polytope(const Statement& statement, const Shape& sh, const Mat3& m, Vec3d t) {
    std::vector<Vec3d> v;
    std::vector<std::vector<int>> faces;
    const int n = sh.fragments;
    auto ring = [&](double radius, double z) {
      const int first = static_cast<int>(v.size());
      for (int j = 0; j < n; ++j) {
        const double a = 2 * kPi * j / n;
        v.push_back({radius * std::cos(a), radius * std::sin(a), z});
      }
      return first;
    };
    if (sh.kind == Shape::Kind::kBox) {
      for (int c = 0; c < 8; ++c)
        v.push_back({(c & 1 ? 0.5 : -0.5) * sh.size.x, (c & 2 ? 0.5 : -0.5) * sh.size.y,
                     (c & 4 ? 0.5 : -0.5) * sh.size.z});
      faces = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    } else if (sh.kind == Shape::Kind::kCylinder) {
      const double r1 = sh.size.x, r2 = sh.size.y, h = sh.size.z;
      const int bottom = r1 > 0 ? ring(r1, -h / 2) : -1, top = r2 > 0 ? ring(r2, h / 2) : -1;
      int apex = -1;
      if (bottom < 0 || top < 0) {
        apex = static_cast<int>(v.size());
        v.push_back({0, 0, bottom < 0 ? -h / 2 : h / 2});
      }
      if (bottom >= 0) faces.push_back({bottom, bottom + 1, bottom + 2});
      if (top >= 0) faces.push_back({top, top + 1, top + 2});
      for (int j = 0; j < n; ++j) {
        const int k = (j + 1) % n;
        if (bottom >= 0 && top >= 0)
          faces.push_back({bottom + j, bottom + k, top + k, top + j});
        else if (bottom >= 0)
          faces.push_back({bottom + j, bottom + k, apex});
        else
          faces.push_back({top + j, top + k, apex});
      }
    } else {  // OpenSCAD's sphere: (n + 1) / 2 rings, ring i at polar angle 180 (i + 1/2) / rings
      const double r = sh.size.x;
      const int rings = (n + 1) / 2;
      for (int i = 0; i < rings; ++i) {
        const double phi = kPi * (i + 0.5) / rings;
        ring(r * std::sin(phi), r * std::cos(phi));
      }
      faces.push_back({0, 1, 2});
      faces.push_back({(rings - 1) * n, (rings - 1) * n + 1, (rings - 1) * n + 2});
      for (int i = 0; i + 1 < rings; ++i)
        for (int j = 0; j < n; ++j)
          faces.push_back({i * n + j, i * n + (j + 1) % n, (i + 1) * n + j});
    }
    Vec3d centroid;
    for (Vec3d& p : v) {
      p = detail::apply(m, p) + t;
      centroid = centroid + p;
    }
    centroid = centroid * (1.0 / static_cast<double>(v.size()));
    planes_ += static_cast<std::int64_t>(faces.size());
    if (planes_ > kMaxPlanes)
      parser_.fail(statement.pos, statement.name + "(): the polytopes need more than " +
                                      std::to_string(kMaxPlanes) +
                                      " planes in all (fewer fragments, or import without facets)");
    require_memory(static_cast<std::uint64_t>(planes_) * kBytesPerPlane, 0, parser_.name(),
                   "a translation of " + std::to_string(planes_) + " planes");
    // The vertices' box first: it leaves the solid as it is (the polytope lies inside it) and gives
    // the model bounds, which an intersection of planes alone does not have.
    Vec3d lo = v[0], hi = v[0];
    for (const Vec3d& p : v)
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::min(lo[a], p[a]);
        hi[a] = std::max(hi[a], p[a]);
      }
    const Vec3d mid = (lo + hi) * 0.5, size = hi - lo;
    std::string out = "(inter (move " + num(mid.x) + " " + num(mid.y) + " " + num(mid.z) +
                      " (box " + num(std::max(size.x, 1e-9)) + " " + num(std::max(size.y, 1e-9)) +
                      " " + num(std::max(size.z, 1e-9)) + "))";
    for (const auto& f : faces) {
      const Vec3d a = v[static_cast<std::size_t>(f[0])], b = v[static_cast<std::size_t>(f[1])],
                  c = v[static_cast<std::size_t>(f[2])];
      Vec3d normal = cross(b - a, c - a);
      if (!(normal.length() > 0)) continue;  // a degenerate face (an apex's neighbours): skip
      normal = normal.normalized();
      if (dot(normal, centroid - a) > 0) normal = normal * -1.0;  // outward
      out += " (plane " + num(normal.x) + " " + num(normal.y) + " " + num(normal.z) + " " +
             num(dot(normal, a)) + ")";
    }
    return out + ")";
  }

  const Parser& parser_;
  const OpenScadOptions& o_;
  std::int64_t planes_ = 0;
};

}  // namespace

std::string translate_openscad_csg(std::string_view text, const std::string& name,
                                   const OpenScadOptions& options) {
  if (text.size() > detail::kMaxModelBytes)
    throw ModelError(name, 1, 1,
                     "file of " + std::to_string(text.size()) + " bytes is over the 64 MiB limit");
  Parser parser(text, name);
  const std::vector<Statement> top = parser.file();
  Translator tr(parser, options);
  // A '!' marks the one subtree OpenSCAD renders.
  std::function<const Statement*(const std::vector<Statement>&)> find_root =
      [&](const std::vector<Statement>& list) -> const Statement* {
    for (const Statement& st : list) {
      if (st.modifier == '!') return &st;
      if (const Statement* r = find_root(st.children)) return r;
    }
    return nullptr;
  };
  Statement root;
  root.name = "group";
  if (const Statement* marked = find_root(top)) {
    root.children = {*marked};
    root.children[0].modifier = 0;
  } else {
    root.children = top;
  }
  const std::string e = tr.convert(root, {}, "");
  if (e.empty())
    throw ModelError(name, 1, 1,
                     "no geometry: the file has no cube, sphere or cylinder that remains");
  return "; translated from " + name + " by voxfield's OpenSCAD import\n" + e + "\n";
}

Model parse_openscad_csg(std::string_view text, const std::string& name,
                         const OpenScadOptions& options) {
  const std::string translated = translate_openscad_csg(text, name, options);
  try {
    Model m = parse_model_sexpr(translated, name + " (translated)");
    m.name = name;
    return m;
  } catch (const ModelError& e) {
    // Numbers out of the language's range (sizes past 1e12, say) surface here.
    throw ModelError(name, 1, 1, std::string("cannot be translated: ") + e.what());
  }
}

}  // namespace voxfield::csg
