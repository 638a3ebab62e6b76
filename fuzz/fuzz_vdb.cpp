// libFuzzer harness for voxfield's own .vdb reader: any input must parse or throw voxfield::Error;
// whatever parses must give each grid's bounds and a dense box of its values, and make a world or
// be refused with an Error. The same bytes are read again clipped to the lower half of the first
// grid's stored bounds (an MPI rank's slab: the other leaves' values stepped over), which must
// give the same bounds and a world of its own or an Error.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

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
  try {
    const voxfield::VdbFile topology =
        voxfield::decode_vdb({data, size}, "fuzz.vdb", {0, voxfield::Box3i{}});
    if (topology.grids.empty()) return 0;
    voxfield::Box3i lower = topology.grids.front().stored_bounds();
    lower.end.z = lower.begin.z + (lower.end.z - lower.begin.z) / 2;
    const voxfield::VdbFile part = voxfield::decode_vdb({data, size}, "fuzz.vdb", {0, lower});
    for (std::size_t i = 0; i < part.grids.size(); ++i)
      if (part.grids[i].stored_bounds() != topology.grids[i].stored_bounds()) std::abort();
    (void)voxfield::world_from_vdb(part, "fuzz.vdb", 8);
  } catch (const voxfield::Error&) {
  }
  return 0;
}
