// libFuzzer harness for the edit-script parser: any input must parse or throw voxfield::Error;
// every edit that parses is applied to a small bounded world (brushes clipped to it), which must
// not fail on a validated edit.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz_common.h"
#include "voxfield/edit_script.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  voxfield::EditScriptOptions o;
  o.load_stamps = false;  // stamps name files; the parser's checks are what is fuzzed
  std::vector<voxfield::Edit> edits;
  try {
    edits = voxfield::parse_edit_script({data, size}, "fuzz.jsonl", o);
  } catch (const voxfield::Error&) {
    return 0;
  }
  voxfield::World world(8, voxfield::Box3i::from_size({24, 24, 24}));
  for (const voxfield::Edit& e : edits) {
    if (std::holds_alternative<voxfield::StampBrush>(e.brush)) continue;
    try {
      (void)voxfield::apply_edit(world, e);
    } catch (const voxfield::Error&) {
      std::abort();  // the parser accepted an edit that apply_edit refuses
    }
  }
  return 0;
}
