// libFuzzer harness for the CSG model language (S-expressions and JSON): any input must parse or
// throw voxfield::Error. A model that parses is compiled and checked against itself: the tape
// equals the reference evaluation, and in a few cells the clipped tape equals the whole tape bit
// for bit and its bounds hold — a soundness check of clipping on whatever models the fuzzer finds.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "fuzz_common.h"
#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace voxfield;
  using namespace voxfield::csg;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  Model model;
  try {
    model = parse_model(text, "fuzz.sdf");
  } catch (const Error&) {
    return 0;
  }
  // Large expansions are legal but slow to check: the parser's limits are what is fuzzed there.
  if (model_info(model).nodes > 2000) return 0;
  const Tape tape = compile_tape(model);
  const Vec3d points[] = {{0, 0, 0}, {0.5, -0.25, 1}, {-3, 2, 0.1}, {10, 10, 10}};
  for (const Vec3d& p : points) {
    const double want = evaluate(model, p), got = evaluate(tape, p);
    if (std::isnan(want) != std::isnan(got)) std::abort();
    if (!std::isnan(want) && std::abs(want - got) > 1e-6 * (1 + std::abs(want))) std::abort();
  }
  const Bounds cells[] = {
      {{-1, -1, -1}, {1, 1, 1}}, {{0.25, -0.5, 0.5}, {0.75, 0, 1.5}}, {{-4, 1, -1}, {-2, 3, 1}}};
  for (const Bounds& cell : cells) {
    const Clipped c = clip(tape, cell);
    for (const Vec3d& p :
         {cell.lo, cell.hi, (cell.lo + cell.hi) * 0.5, cell.lo * 0.7 + cell.hi * 0.3}) {
      const double whole = evaluate(tape, p), pruned = evaluate(c.tape, p);
      if (std::isnan(whole)) continue;
      if (whole != pruned) std::abort();
      if (!(c.lo <= whole && whole <= c.hi)) std::abort();
    }
  }
  return 0;
}
