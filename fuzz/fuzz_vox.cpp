// libFuzzer harness for the .vox reader: any input must parse or throw voxfield::Error; whatever
// parses must encode and parse back to the same voxels.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <utility>
#include <vector>

#include "fuzz_common.h"
#include "voxfield/vox.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // The import options follow from the input's length, so every input replays the same way: most
  // runs use chunks of 8 (per-voxel work under the sanitizers scales with the chunks touched),
  // one in four the default 32; one in two also imports hidden nodes and layers.
  voxfield::VoxImportOptions options;
  options.chunk_edge = size % 4 == 0 ? 32 : 8;
  options.include_hidden = size % 2 == 1;
  // Refusals past 32 MiB are exercised all the same; below it, instancing can still build worlds
  // of tens of millions of voxels from a few kilobytes.
  options.memory_limit_bytes = std::uint64_t{32} << 20;
  try {
    const voxfield::VoxImport in = voxfield::parse_vox({data, size}, "fuzz.vox", options);
    // The round trip through the writer is checked for worlds whose content box holds at most
    // 2^16 voxels: the writer reads that box densely, and beyond it the harness would measure
    // the writer's speed rather than the parser (the parser has already run on the input).
    const voxfield::Box3i content = in.world.voxels.content_bounds();
    if (content.volume() > (std::int64_t{1} << 16)) return 0;
    // A slab of the world (as each rank of an MPI job reads it): the lower half of the content
    // and no more.
    if (!content.empty()) {
      voxfield::VoxImportOptions half = options;
      const int mid = content.begin.z + (content.end.z - content.begin.z + 1) / 2;
      half.keep_z = std::pair<std::int32_t, std::int32_t>{content.begin.z, mid};
      const voxfield::VoxImport slab = voxfield::parse_vox({data, size}, "fuzz.vox", half);
      const voxfield::Box3i got = slab.world.voxels.content_bounds();
      if (got.empty() || got.end.z > mid || got.begin.z != content.begin.z) std::abort();
    }
    const voxfield::VoxImport back =
        voxfield::parse_vox(voxfield::encode_vox(in.world), "fuzz-reencoded.vox", options);
    if (back.world.solid_count() != in.world.solid_count() ||
        !(back.world.voxels.content_bounds() == content)) {
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
