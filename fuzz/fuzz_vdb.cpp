// libFuzzer harness for voxfield's own .vdb reader: any input must parse or throw voxfield::Error;
// whatever parses must give each grid's bounds and a dense box of its values, and make a world or
// be refused with an Error.
#include <algorithm>
#include <cstddef>
#include <cstdint>

#include "fuzz_common.h"
#include "voxfield/vdb.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const voxfield::VdbFile file = voxfield::decode_vdb({data, size}, "fuzz.vdb");
    for (const voxfield::VdbGrid& g : file.grids) {
      const voxfield::Box3i stored = g.stored_bounds();
      (void)g.active_bounds();
      // A corner of the stored region, at most 16^3 voxels, so every tile and leaf path runs.
      voxfield::Box3i box{stored.begin, stored.begin + voxfield::Vec3i::splat(16)};
      (void)g.dense(box.intersect(stored));
    }
    (void)voxfield::world_from_vdb(file, "fuzz.vdb", 8);
  } catch (const voxfield::Error&) {
  }
  return 0;
}
