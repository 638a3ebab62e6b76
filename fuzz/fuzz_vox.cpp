// libFuzzer harness for the .vox reader: any input must parse or throw voxfield::Error; whatever
// parses must encode and parse back to the same voxels.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "fuzz_common.h"
#include "voxfield/vox.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const voxfield::VoxImport in = voxfield::parse_vox({data, size}, "fuzz.vox");
    // The round trip through the writer (which tiles the content in 256^3 models) is checked for
    // worlds of a few hundred chunks: beyond, it measures the writer's speed, not the parser.
    if (in.world.voxels.chunk_count() > 256) return 0;
    const voxfield::VoxImport back =
        voxfield::parse_vox(voxfield::encode_vox(in.world), "fuzz-reencoded.vox");
    if (back.world.solid_count() != in.world.solid_count() ||
        !(back.world.voxels.content_bounds() == in.world.voxels.content_bounds())) {
      std::abort();
    }
    // Voxel for voxel, chunk by chunk (dense copies: a per-voxel get() is too slow under ASan).
    std::vector<std::uint8_t> a, b;
    for (const voxfield::Vec3i c : in.world.voxels.chunk_coords()) {
      const voxfield::Box3i box = in.world.voxels.chunk_view(c).box;
      a.resize(static_cast<std::size_t>(box.volume()));
      b.resize(a.size());
      in.world.voxels.copy_to_dense(box, a.data());
      back.world.voxels.copy_to_dense(box, b.data());
      if (a != b) std::abort();
    }
  } catch (const voxfield::Error&) {
  }
  return 0;
}
