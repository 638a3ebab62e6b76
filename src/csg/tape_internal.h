// voxfield CSG — what the compiler's files share about tapes beyond the public header.
#pragma once

#include <cstddef>

#include "voxfield/csg_compile.h"

namespace voxfield::csg::detail {

// Values of one shape instruction (constants at c) at `count` points.
void shape_values(const Instr& in, const double* c, const Vec3d* points, std::size_t count,
                  double* out);

// How many constants an instruction reads from the parameter array.
int param_count(const Instr& in);

inline bool is_binary(OpCode op) {
  return op == OpCode::kMin || op == OpCode::kMax || op == OpCode::kSmoothMin ||
         op == OpCode::kSmoothMax;
}

}  // namespace voxfield::csg::detail
