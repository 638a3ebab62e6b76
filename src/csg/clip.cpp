// voxfield CSG — clipping a tape to a cell: which branches can matter there, after the
// min/max choice recording of libfive (Keeter, "Massively Parallel Rendering of Complex Closed-Form
// Implicit Surfaces", SIGGRAPH 2020) and fidget, with bounds from Lipschitz constants where they
// hold (Palecek's clip test, made sound: a 1-Lipschitz value over a box lies within its centre
// value plus or minus the half-diagonal) and interval arithmetic where they do not (the ellipsoid).
//
// Soundness: an operand of a min is dropped only when the other operand's upper bound is at most
// its lower bound over the whole cell, so the min equals the kept operand at every point of the
// cell, bit for bit (the same instructions compute it); likewise for max, and for the smooth
// blends once the operands are k apart (their blend term is then exactly zero). Every bound is
// widened by 1e-12 of the magnitudes that computed it (coordinates, constants, the value) to cover
// the rounding of the values it bounds.
#include <algorithm>
#include <cmath>

#include "csg/shapes.h"
#include "csg/tape_internal.h"
#include "voxfield/csg_compile.h"

namespace voxfield::csg {

const char* cell_state_name(CellState state) {
  switch (state) {
    case CellState::kEmpty:
      return "empty";
    case CellState::kFull:
      return "full";
    case CellState::kSurface:
      return "surface";
  }
  return "?";
}

namespace {

using detail::Interval;
using detail::is_binary;
using detail::param_count;

constexpr double kWiden = 1e-12;

// Interval arithmetic on the ellipsoid's formula over the cell mapped into its frame.
Interval ellipsoid_interval(const double* c, const Bounds& cell) {
  const double* r = c + kShapeFrameParams;
  Interval q[3];
  for (int i = 0; i < 3; ++i) {
    double lo = c[9 + i], hi = c[9 + i];
    for (int j = 0; j < 3; ++j) {
      const double m = c[i * 3 + j];
      lo += std::min(m * cell.lo[j], m * cell.hi[j]);
      hi += std::max(m * cell.lo[j], m * cell.hi[j]);
    }
    q[i] = {lo, hi};
  }
  Interval k0sq{0, 0}, k1sq{0, 0};
  for (int i = 0; i < 3; ++i) {
    k0sq = k0sq + detail::square(detail::scaled(q[i], 1 / r[i]));
    k1sq = k1sq + detail::square(detail::scaled(q[i], 1 / (r[i] * r[i])));
  }
  const Interval k0 = detail::sqrt_interval(k0sq), k1 = detail::sqrt_interval(k1sq);
  // k0 (k0 - 1): the product of [a, b] and [a - 1, b - 1], by its corners.
  const double p[4] = {k0.lo * (k0.lo - 1), k0.lo * (k0.hi - 1), k0.hi * (k0.lo - 1),
                       k0.hi * (k0.hi - 1)};
  const Interval num{*std::min_element(p, p + 4), *std::max_element(p, p + 4)};
  // The value is never below -max(r): inside, |k0 (k0 - 1) / k1| <= (1 - k0) max(r) since
  // k1 >= k0 / max(r).
  const double floor = -std::max({r[0], r[1], r[2]});
  Interval v{floor, std::numeric_limits<double>::infinity()};
  if (k1.lo > 0) {
    const double d[4] = {num.lo / k1.lo, num.lo / k1.hi, num.hi / k1.lo, num.hi / k1.hi};
    v = {std::max(floor, *std::min_element(d, d + 4)), *std::max_element(d, d + 4)};
  }
  const double mult = c[12];
  return {v.lo * mult, v.hi * mult};
}

// Which operand a binary instruction keeps over the cell: 0 both, 1 the first, 2 the second.
int choose(OpCode op, Interval a, Interval b, double k) {
  switch (op) {
    case OpCode::kMin:
      return a.hi <= b.lo ? 1 : b.hi < a.lo ? 2 : 0;
    case OpCode::kMax:
      return a.lo >= b.hi ? 1 : b.lo > a.hi ? 2 : 0;
    case OpCode::kSmoothMin:
      return a.hi + k <= b.lo ? 1 : b.hi + k < a.lo ? 2 : 0;
    case OpCode::kSmoothMax:
      return a.lo >= b.hi + k ? 1 : b.lo > a.hi + k ? 2 : 0;
    default:
      return 0;
  }
}

struct Scratch {
  std::vector<Interval> iv;
  std::vector<double> at_centre;
  std::vector<int> material;
  std::vector<std::uint8_t> choice, live;
  std::vector<std::uint32_t> remap;
  std::vector<double> magnitude;
  void resize(std::size_t n) {
    if (iv.size() >= n) return;
    iv.resize(n);
    magnitude.resize(n);
    at_centre.resize(n);
    material.resize(n);
    choice.resize(n);
    live.resize(n);
    remap.resize(n);
  }
};

}  // namespace

Clipped clip(const Tape& tape, const Bounds& cell, double max_distance, bool tape_when_settled) {
  Clipped out;
  clip_into(tape, cell, max_distance, tape_when_settled, out);
  return out;
}

void clip_into(const Tape& tape, const Bounds& cell, double max_distance, bool tape_when_settled,
               Clipped& out) {
  const std::size_t n = tape.code.size();
  const Vec3d centre = (cell.lo + cell.hi) * 0.5;
  const double half_diagonal = (cell.hi - cell.lo).length() * 0.5;
  // Scratch kept per thread: the octree clips millions of small tapes, and allocation would
  // dominate their cost.
  thread_local Scratch scratch;
  scratch.resize(n);
  Interval* iv = scratch.iv.data();
  double* at_centre = scratch.at_centre.data();
  int* material = scratch.material.data();  // constant material over the cell, or -1
  std::uint8_t* choice = scratch.choice.data();
  // How large the numbers computing each value get: rounding errors scale with them, not with
  // the value (a small value at large coordinates carries their rounding).
  double* magnitude = scratch.magnitude.data();
  std::fill_n(choice, n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const Instr& in = tape.code[i];
    const double* c = &tape.params[in.param];
    Interval v{0, 0};
    double centre_value = 0;
    if (in.op == OpCode::kShape) {
      material[i] = in.material;
      double q_max = 0, sizes = 0;
      for (int row = 0; row < 3; ++row) {
        double q = std::abs(c[9 + row]);
        for (int col = 0; col < 3; ++col)
          q += std::abs(c[row * 3 + col]) * (std::abs(centre[col]) + half_diagonal);
        q_max = std::max(q_max, q);
      }
      for (int k = 0; k < shape_param_count(in.shape); ++k)
        sizes += std::abs(c[kShapeFrameParams + k]);
      magnitude[i] = std::abs(c[12]) * (q_max + sizes);
      if (in.lipschitz) {
        detail::shape_values(in, c, &centre, 1, &centre_value);
        v = {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
      } else {
        v = ellipsoid_interval(c, cell);
      }
    } else {
      const Interval a = iv[in.a];
      const double ca = at_centre[in.a];
      const Interval b = is_binary(in.op) ? iv[in.b] : Interval{};
      const double cb = is_binary(in.op) ? at_centre[in.b] : 0;
      const double k = param_count(in) ? c[0] : 0;
      switch (in.op) {
        case OpCode::kMin:
          v = {std::min(a.lo, b.lo), std::min(a.hi, b.hi)};
          centre_value = std::min(ca, cb);
          break;
        case OpCode::kMax:
          v = {std::max(a.lo, b.lo), std::max(a.hi, b.hi)};
          centre_value = std::max(ca, cb);
          break;
        case OpCode::kSmoothMin:
          v = {std::min(a.lo, b.lo) - k / 4, std::min(a.hi, b.hi)};
          centre_value = detail::smooth_min(ca, cb, k);
          break;
        case OpCode::kSmoothMax:
          v = {std::max(a.lo, b.lo), std::max(a.hi, b.hi) + k / 4};
          centre_value = detail::smooth_max(ca, cb, k);
          break;
        case OpCode::kNeg:
          v = {-a.hi, -a.lo};
          centre_value = -ca;
          break;
        case OpCode::kOffset:
          v = a - k;
          centre_value = ca - k;
          break;
        case OpCode::kAbsOffset:
          v = detail::abs_interval(a) - k;
          centre_value = std::abs(ca) - k;
          break;
        case OpCode::kSetMaterial:
        case OpCode::kCopy:
        case OpCode::kShape:
          v = a;
          centre_value = ca;
          break;
      }
      magnitude[i] =
          std::max(magnitude[in.a], is_binary(in.op) ? magnitude[in.b] : 0.0) + std::abs(k);
      choice[i] = static_cast<std::uint8_t>(is_binary(in.op) ? choose(in.op, a, b, k) : 0);
      const bool min_like = in.op == OpCode::kMin || in.op == OpCode::kSmoothMin;
      if (in.op == OpCode::kSetMaterial) {
        material[i] = in.material;
      } else if (min_like && choice[i] == 0) {
        material[i] = material[in.a] == material[in.b] ? material[in.a] : -1;
      } else if (min_like && choice[i] == 2) {
        material[i] = material[in.b];
      } else {
        material[i] = material[in.a];
      }
      // A max dropping its first operand needs that operand's material, constant over the cell.
      if (!min_like && choice[i] == 2 && material[in.a] < 0) choice[i] = 0;
    }
    if (in.lipschitz) {
      v.lo = std::max(v.lo, centre_value - half_diagonal);
      v.hi = std::min(v.hi, centre_value + half_diagonal);
    }
    // Every bound, Lipschitz or interval, widened to cover the rounding of the values it bounds.
    const double widen = kWiden * (std::abs(centre_value) + half_diagonal + magnitude[i]) + 1e-300;
    v.lo -= widen;
    v.hi += widen;
    iv[i] = v;
    at_centre[i] = centre_value;
  }

  const Interval root = iv[n - 1];
  out.lo = root.lo;
  out.hi = root.hi;
  out.material = material[n - 1];
  out.state = (root.lo > 0 || root.lo >= max_distance)    ? CellState::kEmpty
              : (root.hi < 0 || root.hi <= -max_distance) ? CellState::kFull
                                                          : CellState::kSurface;

  // Live instructions, from the result back; a decided min/max passes its kept operand through.
  Tape& t = out.tape;  // its arrays keep their capacity from earlier cells
  t.code.clear();
  t.params.clear();
  if (out.state != CellState::kSurface && !tape_when_settled) return;
  std::uint8_t* live = scratch.live.data();
  std::fill_n(live, n, 0);
  live[n - 1] = 1;
  for (std::size_t i = n; i-- > 0;) {
    if (!live[i]) continue;
    const Instr& in = tape.code[i];
    if (in.op == OpCode::kShape) continue;
    if (choice[i] != 2) live[in.a] = 1;
    if (is_binary(in.op) && choice[i] != 1) live[in.b] = 1;
  }
  std::uint32_t* remap = scratch.remap.data();
  for (std::size_t i = 0; i < n; ++i) {
    if (!live[i]) continue;
    const Instr& in = tape.code[i];
    if (choice[i] == 1) {
      remap[i] = remap[in.a];
      continue;
    }
    if (choice[i] == 2) {
      const bool min_like = in.op == OpCode::kMin || in.op == OpCode::kSmoothMin;
      if (min_like || material[in.a] == material[in.b]) {
        remap[i] = remap[in.b];
        continue;
      }
      Instr set{OpCode::kSetMaterial};
      set.a = remap[in.b];
      set.material = static_cast<std::uint8_t>(material[in.a]);
      set.lipschitz = t.code[set.a].lipschitz;
      t.code.push_back(set);
      remap[i] = static_cast<std::uint32_t>(t.code.size() - 1);
      continue;
    }
    Instr copy = in;
    if (in.op != OpCode::kShape) copy.a = remap[in.a];
    if (is_binary(in.op)) copy.b = remap[in.b];
    copy.param = static_cast<std::uint32_t>(t.params.size());
    const int count = param_count(in);
    t.params.insert(t.params.end(), tape.params.begin() + in.param,
                    tape.params.begin() + in.param + count);
    t.code.push_back(copy);
    remap[i] = static_cast<std::uint32_t>(t.code.size() - 1);
  }
  // The result may be an operand passed through (a pruned min at the root): make the last
  // instruction the result.
  if (remap[n - 1] != t.code.size() - 1) {
    Instr pass{OpCode::kCopy};
    pass.a = remap[n - 1];
    pass.lipschitz = t.code[pass.a].lipschitz;
    t.code.push_back(pass);
  }
  assign_registers(t);
}

}  // namespace voxfield::csg
