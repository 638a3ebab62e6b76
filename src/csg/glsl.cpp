// voxfield CSG — GLSL generation (Palecek, "A Better Approach to SDF Decomposition": one small
// shader per variant, every constant read in order from a parameter buffer so that cells sharing a
// structure share one compiled shader). The generated functions compute the same operations as the
// CPU tape, in float.
#include <sstream>

#include "csg/tape_internal.h"
#include "voxfield/csg_compile.h"
#include "voxfield/error.h"

namespace voxfield::csg {

std::string glsl_prelude() {
  return R"(// voxfield CSG prelude: the shapes of docs/csg.md in their own frames, and the blends.
// The including shader defines float vf_param(uint i), reading the parameter buffer.
float vf_sphere(vec3 p, float r) { return length(p) - r; }
float vf_box(vec3 p, vec3 h) {
  vec3 q = abs(p) - h;
  return length(max(q, 0.0)) + min(max(q.x, max(q.y, q.z)), 0.0);
}
float vf_rounded_box(vec3 p, vec3 h, float r) { return vf_box(p, h - vec3(r)) - r; }
float vf_cylinder(vec3 p, float r, float hh) {
  vec2 d = vec2(length(p.xy) - r, abs(p.z) - hh);
  return min(max(d.x, d.y), 0.0) + length(max(d, 0.0));
}
float vf_capsule(vec3 p, float r, float hh) {
  return length(vec3(p.xy, p.z - clamp(p.z, -hh, hh))) - r;
}
float vf_torus(vec3 p, float R, float r) { return length(vec2(length(p.xy) - R, p.z)) - r; }
float vf_segment2(vec2 q, vec2 a, vec2 b) {
  vec2 pa = q - a, e = b - a;
  float e2 = dot(e, e);
  float t = e2 > 0.0 ? clamp(dot(pa, e) / e2, 0.0, 1.0) : 0.0;
  return length(pa - e * t);
}
float vf_cone(vec3 p, float r, float hh) {
  vec2 q = vec2(length(p.xy), p.z);
  float d = min(vf_segment2(q, vec2(0.0, hh), vec2(r, -hh)), vf_segment2(q, vec2(r, -hh), vec2(0.0, -hh)));
  bool inside = q.y >= -hh && q.y <= hh && q.x * 2.0 * hh <= r * (hh - q.y);
  return inside ? -d : d;
}
float vf_plane(vec3 p, vec3 n, float d) { return dot(p, n) - d; }
float vf_ellipsoid(vec3 p, vec3 r) {
  float k0 = length(p / r), k1 = length(p / (r * r));
  return k1 == 0.0 ? -min(r.x, min(r.y, r.z)) : k0 * (k0 - 1.0) / k1;
}
float vf_smin(float a, float b, float k) {
  float h = max(k - abs(a - b), 0.0) / k;
  return min(a, b) - h * h * k * 0.25;
}
float vf_smax(float a, float b, float k) {
  float h = max(k - abs(a - b), 0.0) / k;
  return max(a, b) + h * h * k * 0.25;
}
)";
}

namespace {

std::string shape_call(NodeKind kind, const std::string& s0, const std::string& s1,
                       const std::string& s2, const std::string& s3) {
  switch (kind) {
    case NodeKind::kSphere:
      return "vf_sphere(q, " + s0 + ")";
    case NodeKind::kBox:
      return "vf_box(q, vec3(" + s0 + ", " + s1 + ", " + s2 + ") * 0.5)";
    case NodeKind::kRoundedBox:
      return "vf_rounded_box(q, vec3(" + s0 + ", " + s1 + ", " + s2 + ") * 0.5, " + s3 + ")";
    case NodeKind::kCylinder:
      return "vf_cylinder(q, " + s0 + ", " + s1 + " * 0.5)";
    case NodeKind::kCapsule:
      return "vf_capsule(q, " + s0 + ", " + s1 + " * 0.5)";
    case NodeKind::kTorus:
      return "vf_torus(q, " + s0 + ", " + s1 + ")";
    case NodeKind::kCone:
      return "vf_cone(q, " + s0 + ", " + s1 + " * 0.5)";
    case NodeKind::kPlane:
      return "vf_plane(q, vec3(" + s0 + ", " + s1 + ", " + s2 + "), " + s3 + ")";
    default:
      return "vf_ellipsoid(q, vec3(" + s0 + ", " + s1 + ", " + s2 + "))";
  }
}

}  // namespace

std::string glsl_variant(const Tape& tape, int index) {
  std::ostringstream g;
  g << "// voxfield CSG variant " << index << ": " << tape.code.size() << " instructions, "
    << tape.params.size() << " parameters read in order from base\n";
  g << "float vf_variant_" << index << "(vec3 p, uint base, out uint material) {\n";
  g << "  vec3 q;\n";
  for (std::uint32_t r = 0; r < tape.registers; ++r) g << "  float r" << r << ";\n";
  // Materials in registers of their own, as the CPU tape keeps them (tape.cpp): each
  // instruction's material is assigned before its value, since its register may be an operand's.
  for (std::uint32_t r = 0; r < tape.registers; ++r) g << "  uint m" << r << ";\n";
  std::uint32_t offset = 0;  // constants are read in instruction order
  auto param = [&](std::uint32_t i) {
    return "vf_param(base + " + std::to_string(offset + i) + "u)";
  };
  for (std::size_t i = 0; i < tape.code.size(); ++i) {
    const Instr& in = tape.code[i];
    const std::string out = "r" + std::to_string(tape.reg[i]);
    const std::string a = in.op == OpCode::kShape ? "" : "r" + std::to_string(tape.reg[in.a]);
    const std::string b = detail::is_binary(in.op) ? "r" + std::to_string(tape.reg[in.b]) : "";
    const std::string mo = "m" + std::to_string(tape.reg[i]);
    const std::string ma = in.op == OpCode::kShape ? "" : "m" + std::to_string(tape.reg[in.a]);
    const std::string mb = detail::is_binary(in.op) ? "m" + std::to_string(tape.reg[in.b]) : "";
    const std::string literal = std::to_string(int{in.material}) + "u";
    switch (in.op) {
      case OpCode::kShape:
      case OpCode::kSetMaterial:
        g << "  " << mo << " = " << literal << ";\n";
        break;
      case OpCode::kMin:
      case OpCode::kSmoothMin:
        g << "  " << mo << " = " << b << " < " << a << " ? " << mb << " : " << ma << ";\n";
        break;
      default:
        g << "  " << mo << " = " << ma << ";\n";
        break;
    }
    switch (in.op) {
      case OpCode::kShape:
        g << "  q = vec3(";
        for (std::uint32_t row = 0; row < 3; ++row)
          g << (row ? ",\n           " : "") << param(row * 3) << " * p.x + " << param(row * 3 + 1)
            << " * p.y + " << param(row * 3 + 2) << " * p.z + " << param(9 + row);
        g << ");\n  " << out << " = " << param(12) << " * "
          << shape_call(in.shape, param(13), param(14), param(15), param(16)) << ";\n";
        break;
      case OpCode::kMin:
        g << "  " << out << " = min(" << a << ", " << b << ");\n";
        break;
      case OpCode::kMax:
        g << "  " << out << " = max(" << a << ", " << b << ");\n";
        break;
      case OpCode::kSmoothMin:
        g << "  " << out << " = vf_smin(" << a << ", " << b << ", " << param(0) << ");\n";
        break;
      case OpCode::kSmoothMax:
        g << "  " << out << " = vf_smax(" << a << ", " << b << ", " << param(0) << ");\n";
        break;
      case OpCode::kNeg:
        g << "  " << out << " = -" << a << ";\n";
        break;
      case OpCode::kOffset:
        g << "  " << out << " = " << a << " - " << param(0) << ";\n";
        break;
      case OpCode::kAbsOffset:
        g << "  " << out << " = abs(" << a << ") - " << param(0) << ";\n";
        break;
      case OpCode::kCopy:
      case OpCode::kSetMaterial:
        g << "  " << out << " = " << a << ";\n";
        break;
    }
    offset += static_cast<std::uint32_t>(detail::param_count(in));
  }
  g << "  material = m" << tape.reg[tape.code.size() - 1] << ";\n";
  g << "  return r" << tape.reg[tape.code.size() - 1] << ";\n}\n";
  return g.str();
}

std::string glsl_variant_kernel(const Tape& tape, int index) {
  std::ostringstream g;
  g << "#version 450\n"
    << "// voxfield CSG: variant " << index << " evaluated at points (one invocation per point)\n"
    << "layout(local_size_x = 64) in;\n"
    << "layout(std430, binding = 0) readonly buffer Params { float vf_params[]; };\n"
    << "// Each point: x, y, z in model units, and the first parameter of its cell (as uint "
       "bits).\n"
    << "layout(std430, binding = 1) readonly buffer Points { vec4 vf_points[]; };\n"
    << "layout(std430, binding = 2) writeonly buffer Values { float vf_values[]; };\n"
    << "layout(push_constant) uniform Push { uint count; } vf_push;\n"
    << "float vf_param(uint i) { return vf_params[i]; }\n"
    << glsl_prelude() << glsl_variant(tape, index) << "void main() {\n"
    << "  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x +\n"
    << "                 gl_GlobalInvocationID.x;\n"
    << "  if (i >= vf_push.count) return;\n"
    << "  const vec4 pt = vf_points[i];\n"
    << "  uint material;\n"
    << "  vf_values[i] = vf_variant_" << index << "(pt.xyz, floatBitsToUint(pt.w), material);\n"
    << "}\n";
  return g.str();
}

std::vector<std::uint32_t> interpreter_program(const Tape& tape) {
  if (tape.code.empty()) throw InvalidArgument("CSG interpreter: an empty tape");
  if (tape.registers > kInterpreterRegisters)
    throw InvalidArgument("CSG interpreter: the tape needs " + std::to_string(tape.registers) +
                          " registers, the interpreter has " +
                          std::to_string(kInterpreterRegisters));
  std::vector<std::uint32_t> program{static_cast<std::uint32_t>(tape.code.size())};
  for (std::size_t i = 0; i < tape.code.size(); ++i) {
    const Instr& in = tape.code[i];
    program.push_back(static_cast<std::uint32_t>(in.op) |
                      (static_cast<std::uint32_t>(in.shape) << 8) |
                      (static_cast<std::uint32_t>(detail::param_count(in)) << 16) |
                      (static_cast<std::uint32_t>(in.material) << 24));
    program.push_back(tape.reg[i]);
    program.push_back(in.op == OpCode::kShape ? 0u : tape.reg[in.a]);
    program.push_back(detail::is_binary(in.op) ? tape.reg[in.b] : 0u);
  }
  return program;
}

std::string glsl_interpreter() {
  std::ostringstream g;
  const auto op = [](OpCode o) { return std::to_string(static_cast<int>(o)) + "u"; };
  g << "// voxfield CSG interpreter: runs the program at vf_program[prog] (interpreter_program's\n"
    << "// layout) at p, its constants read in instruction order from vf_param(at).\n"
    << "// A shape in its own frame, its sizes read from `at` on (only those it has).\n"
    << "float vf_shape(uint kind, vec3 q, uint at) {\n  switch (kind) {\n";
  for (NodeKind k : {NodeKind::kSphere, NodeKind::kBox, NodeKind::kRoundedBox, NodeKind::kCylinder,
                     NodeKind::kCapsule, NodeKind::kTorus, NodeKind::kCone, NodeKind::kPlane,
                     NodeKind::kEllipsoid})
    g << "    case " << static_cast<int>(k) << "u: return "
      << shape_call(k, "vf_param(at)", "vf_param(at + 1u)", "vf_param(at + 2u)",
                    "vf_param(at + 3u)")
      << ";\n";
  g << "  }\n  return 0.0;\n}\n"
    << "float vf_interpret(uint prog, vec3 p, uint at, out uint material) {\n"
    << "  float r[" << kInterpreterRegisters << "];\n"
    << "  uint m[" << kInterpreterRegisters << "];\n"
    << "  uint result = 0u;\n"
    << "  const uint n = vf_program[prog];\n"
    << "  for (uint k = 0u; k < n; ++k) {\n"
    << "    const uint w = vf_program[prog + 1u + 4u * k];\n"
    << "    const uint op = w & 0xFFu, out_r = vf_program[prog + 2u + 4u * k];\n"
    << "    const uint ra = vf_program[prog + 3u + 4u * k], rb = vf_program[prog + 4u + 4u * k];\n"
    << "    const float a = r[ra], b = r[rb];\n"
    << "    // Materials as the CPU tape and the generated variants keep them.\n"
    << "    uint mat = m[ra];\n"
    << "    if (op == " << op(OpCode::kShape) << " || op == " << op(OpCode::kSetMaterial)
    << ") mat = w >> 24;\n"
    << "    else if (op == " << op(OpCode::kMin) << " || op == " << op(OpCode::kSmoothMin)
    << ") mat = b < a ? m[rb] : m[ra];\n"
    << "    float v = a;  // " << op(OpCode::kCopy) << " and " << op(OpCode::kSetMaterial) << "\n"
    << "    if (op == " << op(OpCode::kShape) << ") {\n"
    << "      const vec3 q = vec3(";
  // The same expressions, in the same order, as glsl_variant's.
  for (int row = 0; row < 3; ++row)
    g << (row ? ",\n                          " : "") << "vf_param(at + " << row * 3
      << "u) * p.x + vf_param(at + " << row * 3 + 1 << "u) * p.y + vf_param(at + " << row * 3 + 2
      << "u) * p.z + vf_param(at + " << 9 + row << "u)";
  g << ");\n"
    << "      v = vf_param(at + 12u) * vf_shape((w >> 8) & 0xFFu, q, at + 13u);\n"
    << "    } else if (op == " << op(OpCode::kMin) << ") v = min(a, b);\n"
    << "    else if (op == " << op(OpCode::kMax) << ") v = max(a, b);\n"
    << "    else if (op == " << op(OpCode::kSmoothMin) << ") v = vf_smin(a, b, vf_param(at));\n"
    << "    else if (op == " << op(OpCode::kSmoothMax) << ") v = vf_smax(a, b, vf_param(at));\n"
    << "    else if (op == " << op(OpCode::kNeg) << ") v = -a;\n"
    << "    else if (op == " << op(OpCode::kOffset) << ") v = a - vf_param(at);\n"
    << "    else if (op == " << op(OpCode::kAbsOffset) << ") v = abs(a) - vf_param(at);\n"
    << "    r[out_r] = v;\n"
    << "    m[out_r] = mat;\n"
    << "    result = out_r;\n"
    << "    at += (w >> 16) & 0xFFu;\n"
    << "  }\n"
    << "  material = m[result];\n"
    << "  return r[result];\n"
    << "}\n";
  return g.str();
}

std::string glsl_interpreter_kernel() {
  std::ostringstream g;
  g << "#version 450\n"
    << "// voxfield CSG: the interpreter, running any tape given as a program at points (the\n"
    << "// placeholder for cells whose variant's shader is not compiled yet).\n"
    << "layout(local_size_x = 64) in;\n"
    << "layout(std430, binding = 0) readonly buffer Params { float vf_params[]; };\n"
    << "layout(std430, binding = 1) readonly buffer Points { vec4 vf_points[]; };\n"
    << "layout(std430, binding = 2) writeonly buffer Values { float vf_values[]; };\n"
    << "layout(std430, binding = 3) readonly buffer Program { uint vf_program[]; };\n"
    << "layout(push_constant) uniform Push { uint count; } vf_push;\n"
    << "float vf_param(uint i) { return vf_params[i]; }\n"
    << glsl_prelude() << glsl_interpreter() << "void main() {\n"
    << "  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x +\n"
    << "                 gl_GlobalInvocationID.x;\n"
    << "  if (i >= vf_push.count) return;\n"
    << "  const vec4 pt = vf_points[i];\n"
    << "  uint material;\n"
    << "  vf_values[i] = vf_interpret(0u, pt.xyz, floatBitsToUint(pt.w), material);\n"
    << "}\n";
  return g.str();
}

}  // namespace voxfield::csg
