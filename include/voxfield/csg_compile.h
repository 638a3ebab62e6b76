// voxfield — the voxel compiler: CSG models (csg.h) flattened into tapes, clipped per octree cell
// into small evaluators, grouped into variants by structure, and voxelised.
//
// After Aeva Palecek, "A Better Approach to SDF Decomposition" (2022), the design behind Tangerine:
// fold the transforms so each shape carries one, take every constant out into a parameter buffer
// read in order, clip the tree per cell incrementally down an octree, and de-duplicate the pruned
// trees into variants. Clipping here is sound for every node type: interval bounds per instruction
// (a 1-Lipschitz node's value over a cell lies within its centre value plus or minus the cell's
// half-diagonal; the ellipsoid, which is not 1-Lipschitz, gets interval arithmetic on its formula),
// and a min or max drops an operand only when the other wins everywhere in the cell, as libfive and
// fidget record the choices of their min/max nodes.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "voxfield/csg.h"
#include "voxfield/interrupt.h"
#include "voxfield/world.h"

namespace voxfield::csg {

enum class OpCode : std::uint8_t {
  kShape,        // value = scale * shape(M p + t)
  kMin,          // min(a, b); material of the smaller (the first on ties)
  kMax,          // max(a, b); material of a
  kSmoothMin,    // smooth_min(a, b, k); material of the smaller
  kSmoothMax,    // smooth_max(a, b, k); material of a
  kNeg,          // -a
  kOffset,       // a - r           (round)
  kAbsOffset,    // |a| - r         (shell, with r = t/2)
  kSetMaterial,  // a, with material m (a pruned max whose dropped first operand gave the material)
  kCopy,         // a (a pruned tape's result when it is an earlier value)
};

struct Instr {
  OpCode op = OpCode::kShape;
  NodeKind shape = NodeKind::kSphere;  // kShape
  bool lipschitz = true;               // the value is 1-Lipschitz (no ellipsoid beneath)
  std::uint8_t material = 0;           // kShape, kSetMaterial
  std::uint32_t a = 0, b = 0;          // operands: indices of earlier instructions
  std::uint32_t param = 0;             // index of the first constant in Tape::params
  std::uint32_t source = 0;            // the instruction of the whole tape this one came from
};

// Constants of a shape instruction: the 3x3 matrix (row major) and translation taking a point into
// the shape's frame, the distance scale, then the shape's own parameters (sizes as written).
inline constexpr int kShapeFrameParams = 13;
int shape_param_count(NodeKind kind);  // the shape's own

// A straight-line program: instructions in evaluation order, the last one the model's value.
struct Tape {
  std::vector<Instr> code;
  std::vector<double> params;
  // Registers for batched evaluation (filled by assign_registers): reg[i] holds instruction i's
  // values; instructions reuse the registers of values no longer needed.
  std::vector<std::uint32_t> reg;
  std::uint32_t registers = 0;
};
void assign_registers(Tape& tape);

// The model with its transforms folded into its shapes (throws ResourceLimitError past the memory
// limit, 0: the process default).
Tape compile_tape(const Model& model, std::uint64_t memory_limit_bytes = 0);

// The tape's value at one point, and at many (`materials`, when not empty, gets the material of
// each point: the paint of the winning branch).
double evaluate(const Tape& tape, Vec3d p);
void evaluate(const Tape& tape, std::span<const Vec3d> points, std::span<double> values,
              std::span<std::uint8_t> materials = {});
// The same with the constants taken from `params` instead of tape.params (a variant's structure
// with one cell's constants).
void evaluate(const Tape& tape, const double* params, std::span<const Vec3d> points,
              std::span<double> values, std::span<std::uint8_t> materials = {});

enum class CellState : std::uint8_t { kEmpty, kFull, kSurface };
const char* cell_state_name(CellState state);

struct Clipped {
  CellState state = CellState::kSurface;
  // The tape pruned to the branches that can matter in the cell (in every state): it equals the
  // whole tape at every point of the cell, value and material (same operations on the same
  // values, so bit for bit).
  Tape tape;
  // Bounds of the value over the cell. kEmpty: lo > 0 (or lo >= max_distance); kFull: hi < 0 (or
  // hi <= -max_distance).
  double lo = 0, hi = 0;
  // The material over the cell when it is one constant (from the paints), else -1.
  int material = -1;
};
// The tape clipped to a box. Cells whose value is at least `max_distance` from zero everywhere
// also count as empty or full (callers clamping at that distance need no more). Without
// `tape_when_settled`, empty and full cells come without a tape (cheaper when none is needed).
Clipped clip(const Tape& tape, const Bounds& cell,
             double max_distance = std::numeric_limits<double>::infinity(),
             bool tape_when_settled = true);
// The same into `out`, reusing the memory of its tape (for loops clipping many cells).
void clip_into(const Tape& tape, const Bounds& cell, double max_distance, bool tape_when_settled,
               Clipped& out);

// A tape's structure (opcodes, shapes, materials and wiring, without the numeric constants): equal
// keys share one generated evaluator. structure_hash is a 64-bit digest of it and same_structure
// the exact test.
std::string structure_key(const Tape& tape);
std::uint64_t structure_hash(const Tape& tape);
bool same_structure(const Tape& a, const Tape& b);

struct OctreeOptions {
  int depth = 6;              // leaves at most this many halvings below the root (0..8)
  std::optional<Bounds> box;  // default: the model's bounds made cubic
  double max_distance = std::numeric_limits<double>::infinity();
  Interrupter* interrupter = nullptr;
  std::uint64_t memory_limit_bytes = 0;  // leaves and their sources (0: the process default)
};

struct OctreeLeaf {
  std::uint16_t x = 0, y = 0, z = 0;  // the cell's index among the 2^level per axis at its level
  std::uint8_t level = 0;
  CellState state = CellState::kSurface;
  std::int32_t variant = -1;        // kSurface
  std::int64_t source_offset = -1;  // kSurface: its instructions' origins in Octree::sources
  double lo = 0, hi = 0;
};

struct Variant {
  std::string key;
  Tape tape;  // the structure, with the constants of its first cell
  std::int64_t cells = 0;
};

struct CompileStats {
  std::int64_t cells_visited = 0, leaves = 0, empty = 0, full = 0, surface = 0, variants = 0;
  std::int64_t whole_nodes = 0, max_nodes = 0;
  double mean_nodes = 0;  // per surface leaf
  double octree_ms = 0;
};

// The model's octree: each child clips its parent's pruned tape; cells found empty or full stop
// early, surface cells are split until `depth`.
struct Octree {
  Bounds root;
  int depth = 0;
  std::vector<OctreeLeaf> leaves;
  std::vector<Variant> variants;
  Tape whole;  // the tape the octree was built from
  // For each surface leaf, in leaf order, the whole tape's instruction behind each instruction of
  // its variant: enough to rebuild its constants (leaf_params) without storing them per cell.
  std::vector<std::uint32_t> sources;
  CompileStats stats;
  std::uint64_t id = 0;  // distinct per build (keys the per-thread caches of leaf tapes)
  // Child links: node 0 is the root; entries >= 0 are nodes (8 children each, in `children`),
  // entries < 0 are leaves -(leaf + 1).
  std::vector<std::int32_t> children;

  // The leaf containing p (nullopt outside the root).
  std::optional<int> leaf_at(Vec3d p) const;
  // A leaf's box.
  Bounds leaf_box(const OctreeLeaf& leaf) const;
  // A surface leaf's constants, in the order its variant reads them (Palecek's parameter buffer
  // holds these for every cell), and its pruned tape (the variant with these constants).
  std::vector<double> leaf_params(const OctreeLeaf& leaf) const;
  Tape leaf_tape(const OctreeLeaf& leaf) const;
  // The value through p's cell: its pruned tape in surface cells; in empty or full cells the
  // cell's bound nearest zero (right sign, magnitude at most the whole tape's); the whole tape
  // outside the root. Leaf tapes are cached per thread, so nearby queries cost one evaluation.
  double evaluate(Vec3d p) const;
  // The exact value (the whole tape's, bit for bit): through p's cell's pruned tape in surface
  // cells, the whole tape elsewhere.
  double exact_value(Vec3d p) const;
};
Octree build_octree(const Tape& tape, const Model& model, const OctreeOptions& options);

// ---- voxelisation -------------------------------------------------------------------------------

struct VoxelizeOptions {
  double voxel_size = 1;
  std::optional<Bounds> box;  // default: the model's bounds
  // Clamp the field to +-max_distance; cells farther than it from the surface are filled without
  // evaluating anything.
  double max_distance = std::numeric_limits<double>::infinity();
  bool field = false;  // also keep the value at each voxel centre
  bool prune = true;   // false: evaluate the whole tape at every voxel (for comparison)
  int leaf_edge = 8;   // voxels per leaf cell edge
  std::uint64_t memory_limit_bytes = 0;
  Interrupter* interrupter = nullptr;
};

struct VoxelizeStats {
  std::int64_t voxels = 0, evaluated = 0, cells = 0, empty_cells = 0, full_cells = 0,
               surface_cells = 0;
  double mean_nodes = 0;
  std::int64_t max_nodes = 0, whole_nodes = 0;
  double ms = 0;
};

// Voxel (i, j, k) has its centre at box.lo + (i + 1/2, j + 1/2, k + 1/2) * voxel_size — the
// world's frame (origin box.lo, that voxel size), so its meshes land in model units; it is solid
// (its material from the paints) where the model's value there is <= 0. `field`, x fastest, holds
// that value in model units (clamped to +-max_distance when given).
struct Voxelized {
  World world;
  Vec3i dims;
  Bounds box;
  std::vector<float> field;
  VoxelizeStats stats;
};
Voxelized voxelize(const Model& model, const VoxelizeOptions& options);

// ---- code generation
// ------------------------------------------------------------------------------

// GLSL shared by every generated evaluator: the shapes and blends (float), and vf_param(i) reading
// the parameter buffer.
std::string glsl_prelude();
// One variant as `float vf_variant_N(vec3 p, uint base, out uint material)`, its constants read in
// order from vf_param(base + ...), with the material of the winning branch as the CPU tape gives
// it.
std::string glsl_variant(const Tape& tape, int index);
// A whole compute shader evaluating one variant at points, ready for SPIR-V (gpu::
// compile_compute_shader): binding 0 the parameter buffer (float), binding 1 the points (vec4:
// x, y, z in model units and, as uint bits in w, the first parameter of the point's cell),
// binding 2 the values (float); a push constant with the number of points; 64 invocations a group.
std::string glsl_variant_kernel(const Tape& tape, int index);
// The interpreter (Palecek's placeholder for cells whose variant's shader is not compiled yet):
// one fixed compute shader running any tape, given as a program, at points — the bindings of
// glsl_variant_kernel plus binding 3, the program (uint).
std::string glsl_interpreter_kernel();
// The interpreter as a function, `float vf_interpret(uint prog, vec3 p, uint at, out uint
// material)`, running the program at vf_program[prog] (the including shader declares the uint
// buffer vf_program and vf_param; glsl_prelude() comes first).
std::string glsl_interpreter();
// A tape as the interpreter's program: its instruction count, then four words per instruction
// (op | shape << 8 | constants << 16 | material << 24, its register, its operands' registers).
// Throws InvalidArgument for a tape needing more than kInterpreterRegisters registers.
inline constexpr std::uint32_t kInterpreterRegisters = 64;
std::vector<std::uint32_t> interpreter_program(const Tape& tape);

}  // namespace voxfield::csg
