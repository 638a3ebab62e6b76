// voxfield — CSG models: trees of signed-distance shapes, booleans, transforms and modifiers,
// written as S-expressions or the same tree as JSON (docs/csg.md).
//
// A model is what the voxel compiler (csg_compile.h) prunes per octree cell and turns into small
// evaluators. This header holds the model as written: its parser, its definition as a function
// (evaluate(): the reference every compiled form is tested against), the exact/bound label of each
// node and the model's bounds.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "voxfield/box.h"
#include "voxfield/error.h"
#include "voxfield/world.h"

namespace voxfield::csg {

// A model text was malformed: the message reads "NAME:LINE:COLUMN: what" (lines and columns count
// from 1, columns in bytes).
class ModelError : public Error {
 public:
  ModelError(const std::string& name, int line, int column, const std::string& what)
      : Error(name + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + what),
        line_(line),
        column_(column) {}
  int line() const { return line_; }
  int column() const { return column_; }

 private:
  int line_, column_;
};

enum class NodeKind : std::uint8_t {
  // Shapes, centred at the origin; sizes are full extents (docs/csg.md gives each distance).
  kSphere,      // r
  kBox,         // x y z           ((cube s) is (box s s s))
  kRoundedBox,  // x y z r
  kCylinder,    // r h             (axis z)
  kCapsule,     // r h             (segment along z)
  kTorus,       // R r             (in the xy plane)
  kCone,        // r h             (apex at z = h/2, base radius r at z = -h/2)
  kPlane,       // nx ny nz d      (n normalised when parsed)
  kEllipsoid,   // rx ry rz        (radii; an approximation, see Label)
  // Booleans, n-ary, folded left.
  kUnion,
  kInter,
  kDiff,
  kSmoothUnion,  // k
  kSmoothInter,  // k
  kSmoothDiff,   // k
  // Transforms of their one child.
  kMove,    // x y z
  kRotate,  // deg ax ay az        (rotate-x/y/z are rotations about that axis; axis normalised)
  kScale,   // s > 0
  // Modifiers of their one child.
  kRound,  // r: A - r
  kShell,  // t: |A| - t/2
  kPaint,  // material: the node's `material`
};

const char* kind_name(NodeKind kind);  // the language's keyword: "sphere", "smooth-union", ...
bool is_shape(NodeKind kind);
bool is_boolean(NodeKind kind);

// What a node's value is (after Inigo Quilez's catalogue of distance functions):
// - exact: the true signed Euclidean distance to the node's surface;
// - bound: a lower bound of |distance| with the right sign (and a Lipschitz constant of 1), so
//   sphere tracing is safe;
// - approximate: right in sign and zero on the surface only (the ellipsoid and what contains it).
// docs/csg.md gives the propagation rules.
enum class Label : std::uint8_t { kExact, kBound, kApproximate };
const char* label_name(Label label);

// Where a node was written.
struct SourcePos {
  int line = 0, column = 0;
};

struct Node {
  NodeKind kind = NodeKind::kSphere;
  std::vector<double> params;  // the numbers in the order written (normalised axes and normals)
  std::vector<int> children;   // indices of earlier nodes in Model::nodes
  std::uint8_t material = 0;   // kPaint only: 1..255
  SourcePos pos;
};

// Material of everything no paint reaches.
inline constexpr std::uint8_t kDefaultMaterial = 1;

// The model: nodes stored children first; a name defined once and used twice is one node
// referenced twice (a DAG), so models with repeated parts stay small.
struct Model {
  std::string name;  // the file it came from, for messages
  std::vector<Node> nodes;
  int root = -1;
  // Palette for voxelisation: the default palette, with each "#rrggbb" paint given an index (from
  // 255 down, skipping indices painted by number and the default material).
  Palette palette = default_palette();
};

// Parses the S-expression form (docs/csg.md): zero or more (define NAME EXPR) forms and exactly one
// model expression. Throws ModelError with the line and column of the offending token.
Model parse_model_sexpr(std::string_view text, const std::string& name);
// Parses the JSON form: the same forms as arrays (["sphere", 1], ["define", "name", [...]]); the
// top level is one form or an array of forms. Throws ModelError with line and column.
Model parse_model_json(std::string_view text, const std::string& name);
// JSON when the first non-blank character is '[', the S-expression form otherwise.
Model parse_model(std::string_view text, const std::string& name);

// OpenSCAD's flattened CSG tree (`openscad -o model.csg`): group, union, difference,
// intersection, render, multmatrix, color, cube, sphere and cylinder, translated into the model
// language (docs/csg.md says how). Spheres and cylinders are the ideal shapes unless `facets`,
// which gives OpenSCAD's own polytopes ($fn, $fa, $fs as OpenSCAD counts fragments). Other nodes
// (hull, minkowski, polyhedron, extrusions, import, text, 2-D shapes) are refused by name with
// their line. Throws ModelError.
struct OpenScadOptions {
  bool facets = false;
};
Model parse_openscad_csg(std::string_view text, const std::string& name,
                         const OpenScadOptions& options = {});
// The translation itself (model-language text), for reading or keeping.
std::string translate_openscad_csg(std::string_view text, const std::string& name,
                                   const OpenScadOptions& options = {});

// The model's value at p: the definitions of docs/csg.md applied node by node in double
// precision. This is the reference; compiled evaluators equal it within float rounding.
double evaluate(const Model& model, Vec3d p);
// The value of node `node` at p.
double evaluate_node(const Model& model, int node, Vec3d p);
// The material at p (meaningful where the value is <= 0): the innermost paint of the winning
// branch of each union, of the first operand of each intersection and difference.
std::uint8_t material_at(const Model& model, Vec3d p);

Label label_of(const Model& model, int node);

// An axis-aligned box in model units.
struct Bounds {
  Vec3d lo, hi;
  bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }
};
// A box containing the model's surface and everything inside it, or nullopt when the model is
// unbounded (a plane, the outside of a difference with nothing to cut from...).
std::optional<Bounds> model_bounds(const Model& model);

struct ModelInfo {
  std::int64_t nodes = 0;         // in the tree as written out (shared definitions counted per use)
  std::int64_t unique_nodes = 0;  // stored nodes
  std::int64_t shapes = 0;        // shape leaves in the tree as written out
  Label label = Label::kExact;
  std::optional<Bounds> bounds;
};
ModelInfo model_info(const Model& model);

// The box an operation works in: `box` when given (checked finite, lo <= hi), else the model's
// bounds. Throws InvalidArgument naming the model when it is unbounded and no box is given.
Bounds box_or_bounds(const Model& model, const std::optional<Bounds>& box);

}  // namespace voxfield::csg
