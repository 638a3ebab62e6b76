// voxfield CSG — tapes: the model with its transforms folded into its shapes (Palecek, "A Better
// Approach to SDF Decomposition": each shape carries a single transform, no transform nodes
// remain), flattened into a straight-line program with every constant in one parameter array, and
// its batched evaluation.
//
// Folding: a node is evaluated in a frame q = A p (A affine: rotations, translations and uniform
// scales composed) and contributes mult * value(q). (scale s X) = s X(q / s) multiplies mult by s;
// min, max and negation commute with a positive factor; a smooth blend's k, a rounding's r and a
// shell's t scale with it (s smin_k(a, b) = smin_{sk}(sa, sb)).
#include <algorithm>
#include <cmath>

#include "csg/shapes.h"
#include "csg/tape_internal.h"
#include "voxfield/csg_compile.h"
#include "voxfield/limits.h"

namespace voxfield::csg {

int shape_param_count(NodeKind kind) {
  switch (kind) {
    case NodeKind::kSphere:
      return 1;
    case NodeKind::kBox:
    case NodeKind::kEllipsoid:
      return 3;
    case NodeKind::kRoundedBox:
    case NodeKind::kPlane:
      return 4;
    default:
      return 2;  // cylinder, capsule, torus, cone
  }
}

namespace {

class Folder {
 public:
  Folder(const Model& m, std::uint64_t limit) : m_(m), limit_(limit) {}

  Tape run() {
    (void)fold(m_.root, detail::Affine{}, 1.0, kDefaultMaterial);
    assign_registers(tape_);
    return std::move(tape_);
  }

 private:
  std::uint32_t emit(Instr in) {
    in.source = static_cast<std::uint32_t>(tape_.code.size());
    tape_.code.push_back(in);
    if ((tape_.code.size() & 1023) == 0)
      require_memory(tape_.code.size() * sizeof(Instr) + tape_.params.size() * sizeof(double),
                     limit_, m_.name, "compiling the model");
    return static_cast<std::uint32_t>(tape_.code.size() - 1);
  }
  std::uint32_t param(double v) {
    tape_.params.push_back(v);
    return static_cast<std::uint32_t>(tape_.params.size() - 1);
  }
  std::uint32_t unary(OpCode op, std::uint32_t a, double r) {
    Instr in{op};
    in.a = a;
    in.lipschitz = tape_.code[a].lipschitz;
    if (op != OpCode::kNeg) in.param = param(r);
    return emit(in);
  }

  // A constant after folding the scales above it: refused when it under- or overflowed (nested
  // scales multiply), since the tape would then compute NaN where the model does not.
  double checked(const Node& n, double v) const {
    if (!std::isnormal(v) || std::abs(v) > 1e100 || std::abs(v) < 1e-100)
      throw ModelError(m_.name, n.pos.line, n.pos.column,
                       std::string("(") + kind_name(n.kind) +
                           " ...): the scales above it make a constant of " + std::to_string(v) +
                           " (out of range)");
    return v;
  }

  std::uint32_t fold(int index, const detail::Affine& frame, double mult, std::uint8_t material) {
    const Node& n = m_.nodes[static_cast<std::size_t>(index)];
    if (is_shape(n.kind)) {
      Instr in{OpCode::kShape, n.kind, n.kind != NodeKind::kEllipsoid, material};
      in.param = static_cast<std::uint32_t>(tape_.params.size());
      for (double v : frame.m) param(v);
      param(frame.t.x), param(frame.t.y), param(frame.t.z), param(mult);
      for (int i = 0; i < shape_param_count(n.kind); ++i)
        param(n.params[static_cast<std::size_t>(i)]);
      return emit(in);
    }
    if (is_boolean(n.kind)) {
      const bool smooth = n.kind >= NodeKind::kSmoothUnion;
      const bool is_min = n.kind == NodeKind::kUnion || n.kind == NodeKind::kSmoothUnion;
      const bool negate = n.kind == NodeKind::kDiff || n.kind == NodeKind::kSmoothDiff;
      const OpCode op = smooth ? (is_min ? OpCode::kSmoothMin : OpCode::kSmoothMax)
                               : (is_min ? OpCode::kMin : OpCode::kMax);
      std::uint32_t acc = fold(n.children[0], frame, mult, material);
      for (std::size_t c = 1; c < n.children.size(); ++c) {
        std::uint32_t b = fold(n.children[c], frame, mult, material);
        if (negate) b = unary(OpCode::kNeg, b, 0);
        Instr in{op};
        in.a = acc;
        in.b = b;
        in.lipschitz = tape_.code[acc].lipschitz && tape_.code[b].lipschitz;
        if (smooth) in.param = param(checked(n, n.params[0] * mult));
        acc = emit(in);
      }
      return acc;
    }
    const int child = n.children[0];
    switch (n.kind) {
      case NodeKind::kMove: {
        detail::Affine t;
        t.t = Vec3d{-n.params[0], -n.params[1], -n.params[2]};
        return fold(child, t.after(frame), mult, material);
      }
      case NodeKind::kRotate: {
        const auto r =
            detail::rotation_matrix(n.params[0], {n.params[1], n.params[2], n.params[3]});
        detail::Affine t;  // R^-1 = R^T
        t.m = {r[0], r[3], r[6], r[1], r[4], r[7], r[2], r[5], r[8]};
        return fold(child, t.after(frame), mult, material);
      }
      case NodeKind::kScale: {
        detail::Affine t;
        const double inv = 1.0 / n.params[0];
        t.m = {inv, 0, 0, 0, inv, 0, 0, 0, inv};
        return fold(child, t.after(frame), checked(n, mult * n.params[0]), material);
      }
      case NodeKind::kRound:
        return unary(OpCode::kOffset, fold(child, frame, mult, material),
                     n.params[0] == 0 ? 0.0 : checked(n, n.params[0] * mult));
      case NodeKind::kShell:
        return unary(OpCode::kAbsOffset, fold(child, frame, mult, material),
                     checked(n, n.params[0] / 2 * mult));
      default:  // kPaint
        return fold(child, frame, mult, n.material);
    }
  }

  const Model& m_;
  std::uint64_t limit_;
  Tape tape_;
};

// out may be the operand's own register (register reuse): element-wise, never std::copy.
void copy_materials(const std::uint8_t* from, std::uint8_t* to, std::size_t count) {
  if (from != to)
    for (std::size_t j = 0; j < count; ++j) to[j] = from[j];
}

}  // namespace

namespace detail {

void shape_values(const Instr& in, const double* c, const Vec3d* points, std::size_t count,
                  double* out) {
  const double* s = c + kShapeFrameParams;
  const double mult = c[12];
  auto run = [&](auto&& f) {
    for (std::size_t i = 0; i < count; ++i) {
      const Vec3d p = points[i];
      const Vec3d q{c[0] * p.x + c[1] * p.y + c[2] * p.z + c[9],
                    c[3] * p.x + c[4] * p.y + c[5] * p.z + c[10],
                    c[6] * p.x + c[7] * p.y + c[8] * p.z + c[11]};
      out[i] = mult * f(q);
    }
  };
  using namespace detail;
  switch (in.shape) {
    case NodeKind::kSphere:
      return run([&](Vec3d q) { return sd_sphere(q, s[0]); });
    case NodeKind::kBox:
      return run([&](Vec3d q) { return sd_box(q, s[0] / 2, s[1] / 2, s[2] / 2); });
    case NodeKind::kCylinder:
      return run([&](Vec3d q) { return sd_cylinder(q, s[0], s[1] / 2); });
    case NodeKind::kCapsule:
      return run([&](Vec3d q) { return sd_capsule(q, s[0], s[1] / 2); });
    case NodeKind::kTorus:
      return run([&](Vec3d q) { return sd_torus(q, s[0], s[1]); });
    default:
      return run([&](Vec3d q) { return shape_distance(in.shape, s, q); });
  }
}

int param_count(const Instr& in) {
  switch (in.op) {
    case OpCode::kShape:
      return kShapeFrameParams + shape_param_count(in.shape);
    case OpCode::kSmoothMin:
    case OpCode::kSmoothMax:
    case OpCode::kOffset:
    case OpCode::kAbsOffset:
      return 1;
    default:
      return 0;
  }
}

}  // namespace detail

void assign_registers(Tape& tape) {
  const std::size_t n = tape.code.size();
  thread_local std::vector<std::uint32_t> last_use, free_regs;  // scratch, reused per thread
  last_use.assign(n, 0);
  free_regs.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = tape.code[i];
    last_use[i] = static_cast<std::uint32_t>(i);
    if (in.op != OpCode::kShape) last_use[in.a] = static_cast<std::uint32_t>(i);
    if (detail::is_binary(in.op)) last_use[in.b] = static_cast<std::uint32_t>(i);
  }
  tape.reg.assign(n, 0);
  tape.registers = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = tape.code[i];
    // Operands whose last use is this instruction free their registers before it writes, so a
    // binary instruction may write over one of its operands (element by element, which is safe).
    auto release = [&](std::uint32_t operand) {
      if (last_use[operand] == i) free_regs.push_back(tape.reg[operand]);
    };
    if (in.op != OpCode::kShape) release(in.a);
    if (detail::is_binary(in.op) && in.b != in.a) release(in.b);
    if (free_regs.empty()) {
      tape.reg[i] = tape.registers++;
    } else {
      tape.reg[i] = free_regs.back();
      free_regs.pop_back();
    }
  }
}

Tape compile_tape(const Model& model, std::uint64_t memory_limit_bytes) {
  return Folder(model, memory_limit_bytes).run();
}

double evaluate(const Tape& tape, Vec3d p) {
  double v = 0;
  evaluate(tape, {&p, 1}, {&v, 1});
  return v;
}

void evaluate(const Tape& tape, std::span<const Vec3d> points, std::span<double> values,
              std::span<std::uint8_t> materials) {
  evaluate(tape, tape.params.data(), points, values, materials);
}

void evaluate(const Tape& tape, const double* params, std::span<const Vec3d> points,
              std::span<double> values, std::span<std::uint8_t> materials) {
  constexpr std::size_t kBatch = 64;
  const bool want_materials = !materials.empty();
  // Registers kept per thread: callers evaluate millions of single points (sphere tracing,
  // meshing's crossings), where an allocation per call would cost more than the tape.
  thread_local std::vector<double> regs;
  thread_local std::vector<std::uint8_t> mats;
  if (regs.size() < std::size_t{tape.registers} * kBatch)
    regs.resize(std::size_t{tape.registers} * kBatch);
  if (want_materials && mats.size() < std::size_t{tape.registers} * kBatch)
    mats.resize(std::size_t{tape.registers} * kBatch);
  for (std::size_t start = 0; start < points.size(); start += kBatch) {
    const std::size_t count = std::min(kBatch, points.size() - start);
    for (std::size_t i = 0; i < tape.code.size(); ++i) {
      const Instr& in = tape.code[i];
      double* out = &regs[tape.reg[i] * kBatch];
      std::uint8_t* out_m = want_materials ? &mats[tape.reg[i] * kBatch] : nullptr;
      const double* c = params + in.param;
      if (in.op == OpCode::kShape) {
        detail::shape_values(in, c, &points[start], count, out);
        if (out_m) std::fill(out_m, out_m + count, in.material);
        continue;
      }
      const double* a = &regs[tape.reg[in.a] * kBatch];
      const double* b = &regs[tape.reg[in.b] * kBatch];
      const std::uint8_t* am = want_materials ? &mats[tape.reg[in.a] * kBatch] : nullptr;
      const std::uint8_t* bm = want_materials ? &mats[tape.reg[in.b] * kBatch] : nullptr;
      switch (in.op) {
        case OpCode::kMin:
        case OpCode::kSmoothMin:
          for (std::size_t j = 0; j < count; ++j) {
            const double x = a[j], y = b[j];
            if (out_m) out_m[j] = y < x ? bm[j] : am[j];
            out[j] = in.op == OpCode::kMin ? std::min(x, y) : detail::smooth_min(x, y, c[0]);
          }
          break;
        case OpCode::kMax:
        case OpCode::kSmoothMax:
          for (std::size_t j = 0; j < count; ++j) {
            const double x = a[j], y = b[j];
            if (out_m) out_m[j] = am[j];
            out[j] = in.op == OpCode::kMax ? std::max(x, y) : detail::smooth_max(x, y, c[0]);
          }
          break;
        case OpCode::kNeg:
          for (std::size_t j = 0; j < count; ++j) out[j] = -a[j];
          if (out_m) copy_materials(am, out_m, count);
          break;
        case OpCode::kOffset:
          for (std::size_t j = 0; j < count; ++j) out[j] = a[j] - c[0];
          if (out_m) copy_materials(am, out_m, count);
          break;
        case OpCode::kAbsOffset:
          for (std::size_t j = 0; j < count; ++j) out[j] = std::abs(a[j]) - c[0];
          if (out_m) copy_materials(am, out_m, count);
          break;
        case OpCode::kSetMaterial:
          for (std::size_t j = 0; j < count; ++j) out[j] = a[j];
          if (out_m) std::fill(out_m, out_m + count, in.material);
          break;
        case OpCode::kCopy:
          for (std::size_t j = 0; j < count; ++j) out[j] = a[j];
          if (out_m) copy_materials(am, out_m, count);
          break;
        case OpCode::kShape:
          break;
      }
    }
    const std::uint32_t root = tape.reg[tape.code.size() - 1];
    std::copy_n(&regs[root * kBatch], count, &values[start]);
    if (want_materials) std::copy_n(&mats[root * kBatch], count, &materials[start]);
  }
}

std::string structure_key(const Tape& tape) {
  std::string key;
  key.reserve(tape.code.size() * 10);
  for (const Instr& in : tape.code) {
    key += static_cast<char>(in.op);
    key += static_cast<char>(in.shape);
    key += static_cast<char>(in.material);
    if (in.op == OpCode::kShape) continue;
    key.append(reinterpret_cast<const char*>(&in.a), sizeof in.a);
    key.append(reinterpret_cast<const char*>(&in.b), sizeof in.b);
  }
  return key;
}

std::uint64_t structure_hash(const Tape& tape) {
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a
  auto mix = [&h](std::uint64_t v) {
    for (int i = 0; i < 8; ++i, v >>= 8) h = (h ^ (v & 0xff)) * 1099511628211ull;
  };
  for (const Instr& in : tape.code)
    mix(static_cast<std::uint64_t>(in.op) | static_cast<std::uint64_t>(in.shape) << 8 |
        std::uint64_t{in.material} << 16 |
        (in.op == OpCode::kShape ? 0 : std::uint64_t{in.a} << 24 | std::uint64_t{in.b} << 44));
  return h;
}

bool same_structure(const Tape& a, const Tape& b) {
  if (a.code.size() != b.code.size()) return false;
  for (std::size_t i = 0; i < a.code.size(); ++i) {
    const Instr &x = a.code[i], &y = b.code[i];
    if (x.op != y.op || x.shape != y.shape || x.material != y.material) return false;
    if (x.op != OpCode::kShape && (x.a != y.a || x.b != y.b)) return false;
  }
  return true;
}

}  // namespace voxfield::csg
