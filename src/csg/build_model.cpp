// voxfield CSG — from the syntax tree to the model: keywords, arities, the range of every number,
// names defined before use, colours given palette indices; each refusal names the line and column
// of the token at fault.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <set>

#include "csg/datum.h"

namespace voxfield::csg {
namespace detail {
namespace {

// The expanded tree (every use of a definition counted) may hold at most this many nodes, and be
// this deep: compiling expands it, and the reference evaluation recurses through it.
constexpr std::int64_t kMaxExpandedNodes = std::int64_t{1} << 20;
constexpr int kMaxExpandedDepth = 1024;

enum class Check { kPositive, kNonNegative, kAny };
constexpr double kMinPositive = 1e-12;

struct Syntax {
  NodeKind kind;
  std::vector<const char*> params;  // names of the numbers, in order
  std::vector<Check> checks;
  int children;  // -1: one or more
};

const std::map<std::string, Syntax, std::less<>>& keywords() {
  using C = Check;
  static const std::map<std::string, Syntax, std::less<>> k = {
      {"sphere", {NodeKind::kSphere, {"r"}, {C::kPositive}, 0}},
      {"box", {NodeKind::kBox, {"x", "y", "z"}, {C::kPositive, C::kPositive, C::kPositive}, 0}},
      {"cube", {NodeKind::kBox, {"s"}, {C::kPositive}, 0}},
      {"rounded-box",
       {NodeKind::kRoundedBox,
        {"x", "y", "z", "r"},
        {C::kPositive, C::kPositive, C::kPositive, C::kNonNegative},
        0}},
      {"cylinder", {NodeKind::kCylinder, {"r", "h"}, {C::kPositive, C::kPositive}, 0}},
      {"capsule", {NodeKind::kCapsule, {"r", "h"}, {C::kPositive, C::kNonNegative}, 0}},
      {"torus", {NodeKind::kTorus, {"R", "r"}, {C::kPositive, C::kPositive}, 0}},
      {"cone", {NodeKind::kCone, {"r", "h"}, {C::kPositive, C::kPositive}, 0}},
      {"plane",
       {NodeKind::kPlane, {"nx", "ny", "nz", "d"}, {C::kAny, C::kAny, C::kAny, C::kAny}, 0}},
      {"ellipsoid",
       {NodeKind::kEllipsoid, {"rx", "ry", "rz"}, {C::kPositive, C::kPositive, C::kPositive}, 0}},
      {"union", {NodeKind::kUnion, {}, {}, -1}},
      {"inter", {NodeKind::kInter, {}, {}, -1}},
      {"diff", {NodeKind::kDiff, {}, {}, -1}},
      {"smooth-union", {NodeKind::kSmoothUnion, {"k"}, {C::kPositive}, -1}},
      {"smooth-inter", {NodeKind::kSmoothInter, {"k"}, {C::kPositive}, -1}},
      {"smooth-diff", {NodeKind::kSmoothDiff, {"k"}, {C::kPositive}, -1}},
      {"move", {NodeKind::kMove, {"x", "y", "z"}, {C::kAny, C::kAny, C::kAny}, 1}},
      {"rotate",
       {NodeKind::kRotate, {"deg", "ax", "ay", "az"}, {C::kAny, C::kAny, C::kAny, C::kAny}, 1}},
      {"rotate-x", {NodeKind::kRotate, {"deg"}, {C::kAny}, 1}},
      {"rotate-y", {NodeKind::kRotate, {"deg"}, {C::kAny}, 1}},
      {"rotate-z", {NodeKind::kRotate, {"deg"}, {C::kAny}, 1}},
      {"scale", {NodeKind::kScale, {"s"}, {C::kPositive}, 1}},
      {"round", {NodeKind::kRound, {"r"}, {C::kNonNegative}, 1}},
      {"shell", {NodeKind::kShell, {"t"}, {C::kPositive}, 1}},
      {"paint", {NodeKind::kPaint, {"material"}, {C::kAny}, 1}},
  };
  return k;
}

struct Extent {
  std::int64_t nodes = 1;
  int depth = 1;
};

class Builder {
 public:
  explicit Builder(const std::string& name) { model_.name = name; }

  Model build(const std::vector<Datum>& forms) {
    const Datum* body = nullptr;
    for (const Datum& f : forms) {
      if (f.type == Datum::Type::kList && !f.items.empty() &&
          f.items[0].type == Datum::Type::kSymbol && f.items[0].text == "define") {
        define(f);
        continue;
      }
      if (body)
        fail(f, "a model has one expression (the one at line " + std::to_string(body->pos.line) +
                    "); give the others names with (define NAME EXPR) or combine them");
      body = &f;
    }
    if (!body) fail_at({1, 1}, "no model expression (only definitions, or nothing)");
    model_.root = expression(*body);
    assign_colours();
    return std::move(model_);
  }

 private:
  [[noreturn]] void fail_at(SourcePos p, const std::string& what) const {
    throw ModelError(model_.name, p.line, p.column, what);
  }
  [[noreturn]] void fail(const Datum& d, const std::string& what) const { fail_at(d.pos, what); }

  void define(const Datum& f) {
    if (f.items.size() != 3) fail(f, "(define NAME EXPR) takes a name and one expression");
    const Datum& name = f.items[1];
    if (name.type != Datum::Type::kSymbol) fail(name, "a definition's name must be a symbol");
    if (keywords().count(name.text) || name.text == "define")
      fail(name, "\"" + name.text + "\" is a keyword and cannot be defined");
    if (name.text.starts_with('#')) fail(name, "names cannot start with '#' (that is a colour)");
    if (names_.count(name.text)) fail(name, "\"" + name.text + "\" is already defined");
    names_[name.text] = expression(f.items[2]);
  }

  int expression(const Datum& d) {
    if (d.type == Datum::Type::kSymbol) {
      const auto it = names_.find(d.text);
      if (it != names_.end()) return it->second;
      if (keywords().count(d.text))
        fail(d, "\"" + d.text + "\" needs its arguments: write (" + d.text + " ...)");
      fail(d, "\"" + d.text + "\" is not defined (definitions come before their use)");
    }
    if (d.type != Datum::Type::kList)
      fail(d, "expected a shape or an operation, found a " + describe(d));
    if (d.items.empty()) fail(d, "an empty list is not an expression");
    const Datum& head = d.items[0];
    if (head.type != Datum::Type::kSymbol)
      fail(head, "a form starts with a keyword, not a " + describe(head));
    if (head.text == "define") fail(head, "definitions belong at the top level of the model");
    const auto it = keywords().find(head.text);
    if (it == keywords().end()) fail(head, "unknown shape or operation \"" + head.text + "\"");
    const Syntax& syntax = it->second;
    Node node;
    int colour = -1;  // index into colours_ of a "#rrggbb" paint
    node.kind = syntax.kind;
    node.pos = d.pos;
    const std::size_t n_params = syntax.params.size();
    const std::size_t n_children = d.items.size() - 1 - std::min(d.items.size() - 1, n_params);
    if (d.items.size() - 1 < n_params || (syntax.children == 0 && n_children != 0) ||
        (syntax.children == 1 && n_children != 1) || (syntax.children < 0 && n_children == 0))
      fail(d, "(" + head.text + signature(syntax) + ") got " + std::to_string(d.items.size() - 1) +
                  " argument" + (d.items.size() == 2 ? "" : "s"));
    for (std::size_t i = 0; i < n_params; ++i) {
      const Datum& a = d.items[1 + i];
      if (syntax.kind == NodeKind::kPaint) {
        node.material = material(a, colour);
        continue;
      }
      if (a.type != Datum::Type::kNumber)
        fail(a, "(" + head.text + signature(syntax) + "): " + syntax.params[i] +
                    " must be a number, not a " + describe(a));
      const double v = a.number;
      if ((syntax.checks[i] == Check::kPositive && !(v > 0)) ||
          (syntax.checks[i] == Check::kNonNegative && !(v >= 0)))
        fail(a, "(" + head.text + signature(syntax) + "): " + syntax.params[i] + " must be " +
                    (syntax.checks[i] == Check::kPositive ? "> 0" : ">= 0") + ", got " + shown(a));
      // Positive sizes below 1e-12 would fold (with scales) into constants that underflow.
      if (syntax.checks[i] == Check::kPositive && v < kMinPositive)
        fail(a, "(" + head.text + signature(syntax) + "): " + syntax.params[i] +
                    " must be at least 1e-12, got " + shown(a));
      node.params.push_back(v);
    }
    shape_rules(head, d, node);
    Extent extent;
    for (std::size_t c = 1 + n_params; c < d.items.size(); ++c) {
      const int child = expression(d.items[c]);
      node.children.push_back(child);
      const Extent& e = extents_[static_cast<std::size_t>(child)];
      extent.nodes = std::min(extent.nodes + e.nodes, kMaxExpandedNodes + 1);
      extent.depth = std::max(extent.depth, e.depth + 1);
    }
    if (extent.nodes > kMaxExpandedNodes)
      fail(d, "the model expands to more than 2^20 nodes (definitions count once per use)");
    if (extent.depth > kMaxExpandedDepth)
      fail(d, "the model nests deeper than " + std::to_string(kMaxExpandedDepth) +
                  " levels (definitions included)");
    model_.nodes.push_back(std::move(node));
    extents_.push_back(extent);
    if (colour >= 0) coloured_.push_back({model_.nodes.size() - 1, colour});
    return static_cast<int>(model_.nodes.size() - 1);
  }

  // Rules beyond each number's own range; keyword variants folded into their kinds.
  void shape_rules(const Datum& head, const Datum& d, Node& node) {
    auto& p = node.params;
    const std::string& k = head.text;
    if (k == "cube") p = {p[0], p[0], p[0]};
    if (k == "rounded-box" && p[3] > std::min({p[0], p[1], p[2]}) / 2)
      fail(d.items[4], "(rounded-box x y z r): r must be at most half the smallest extent, got " +
                           shown(d.items[4]));
    if (k == "torus" && p[1] > p[0])
      fail(d.items[2],
           "(torus R r): r must be at most R (a self-intersecting torus has no exact distance)");
    if (k == "rotate-x") p = {p[0], 1, 0, 0};
    if (k == "rotate-y") p = {p[0], 0, 1, 0};
    if (k == "rotate-z") p = {p[0], 0, 0, 1};
    if (k == "rotate" || k == "plane") {
      const std::size_t at = k == "rotate" ? 1 : 0;
      const double len = Vec3d{p[at], p[at + 1], p[at + 2]}.length();
      if (!(len > 1e-12))
        fail(d.items[1 + at],
             "(" + k + "): the " + (k == "rotate" ? "axis" : "normal") + " must not be zero");
      for (std::size_t i = at; i < at + 3; ++i) p[i] /= len;
    }
  }

  std::uint8_t material(const Datum& a, int& colour) {
    if (a.type == Datum::Type::kNumber) {
      if (a.number != std::floor(a.number) || a.number < 1 || a.number > 255)
        fail(a, "(paint M EXPR): M must be a palette index 1..255 or \"#rrggbb\", got " + shown(a));
      const auto m = static_cast<std::uint8_t>(a.number);
      numbered_.insert(m);
      return m;
    }
    if ((a.type == Datum::Type::kSymbol || a.type == Datum::Type::kString) && a.text.size() == 7 &&
        a.text[0] == '#' && std::all_of(a.text.begin() + 1, a.text.end(), [](char c) {
          return std::isxdigit(static_cast<unsigned char>(c));
        })) {
      const Rgba rgba{static_cast<std::uint8_t>(std::stoi(a.text.substr(1, 2), nullptr, 16)),
                      static_cast<std::uint8_t>(std::stoi(a.text.substr(3, 2), nullptr, 16)),
                      static_cast<std::uint8_t>(std::stoi(a.text.substr(5, 2), nullptr, 16)), 255};
      colours_.push_back({rgba, a.pos});
      colour = static_cast<int>(colours_.size() - 1);
      return 0;  // a placeholder, replaced once every numbered paint is known (assign_colours)
    }
    fail(a,
         "(paint M EXPR): M must be a palette index 1..255 or \"#rrggbb\", not a " + describe(a));
  }

  // "#rrggbb" paints take indices from 255 down, skipping numbered paints and the default; equal
  // colours share one.
  void assign_colours() {
    std::map<std::uint32_t, std::uint8_t> index_of;
    int next = 255;
    std::vector<std::uint8_t> resolved;
    for (const auto& [colour, pos] : colours_) {
      const std::uint32_t key =
          (std::uint32_t{colour.r} << 16) | (std::uint32_t{colour.g} << 8) | colour.b;
      auto it = index_of.find(key);
      if (it == index_of.end()) {
        while (next >= 1 &&
               (numbered_.count(static_cast<std::uint8_t>(next)) || next == kDefaultMaterial))
          --next;
        if (next < 1) fail_at(pos, "more colours than the palette's 255 entries");
        it = index_of.emplace(key, static_cast<std::uint8_t>(next--)).first;
        model_.palette[it->second] = colour;
      }
      resolved.push_back(it->second);
    }
    for (const auto& [node, colour] : coloured_)
      model_.nodes[node].material = resolved[static_cast<std::size_t>(colour)];
  }

  static std::string signature(const Syntax& s) {
    std::string out;
    for (const char* p : s.params) out += std::string(" ") + p;
    if (s.children == 1) out += " EXPR";
    if (s.children < 0) out += " EXPR...";
    return out;
  }
  static std::string shown(const Datum& d) {
    if (d.type != Datum::Type::kNumber) return d.text;
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, d.number);
    return std::string(buf, r.ptr);
  }
  static std::string describe(const Datum& d) {
    switch (d.type) {
      case Datum::Type::kList:
        return "list";
      case Datum::Type::kNumber:
        return "number";
      case Datum::Type::kSymbol:
        return "symbol \"" + d.text + "\"";
      default:
        return "string \"" + d.text + "\"";
    }
  }

  Model model_;
  std::vector<Extent> extents_;
  std::map<std::string, int, std::less<>> names_;
  std::set<std::uint8_t> numbered_;
  std::vector<std::pair<Rgba, SourcePos>> colours_;
  std::vector<std::pair<std::size_t, int>> coloured_;  // (paint node, colour read)
};

}  // namespace

Model build_model(const std::vector<Datum>& forms, const std::string& name) {
  return Builder(name).build(forms);
}

}  // namespace detail

Model parse_model_sexpr(std::string_view text, const std::string& name) {
  return detail::build_model(detail::read_sexpr(text, name), name);
}

Model parse_model_json(std::string_view text, const std::string& name) {
  return detail::build_model(detail::read_json(text, name), name);
}

Model parse_model(std::string_view text, const std::string& name) {
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string_view::npos && text[first] == '[') return parse_model_json(text, name);
  return parse_model_sexpr(text, name);
}

}  // namespace voxfield::csg
