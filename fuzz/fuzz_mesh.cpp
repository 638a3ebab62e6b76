// libFuzzer harness for the mesh readers (OBJ, PLY, STL, OFF): the first byte picks the format,
// the rest is the file. Any input must parse or throw voxfield::Error; whatever parses must be a
// valid mesh (every index in range, every position finite) whose winding number can be asked.
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "fuzz_common.h"
#include "voxfield/mesh_read.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static constexpr voxfield::MeshInputFormat kFormats[] = {
      voxfield::MeshInputFormat::kObj, voxfield::MeshInputFormat::kPly,
      voxfield::MeshInputFormat::kStl, voxfield::MeshInputFormat::kOff};
  const voxfield::MeshInputFormat format = kFormats[data[0] % 4];
  try {
    const voxfield::TriangleMesh m =
        voxfield::parse_mesh({data + 1, size - 1}, format, "fuzz.mesh");
    m.validate();  // a reader that lets a bad index or a NaN through fails here, loudly
    if (!m.triangles.empty() && m.triangles.size() < 4096) {
      const voxfield::WindingNumber w(m);
      const auto b = m.bounds();
      (void)w.inside({(b[0][0] + b[1][0]) / 2, (b[0][1] + b[1][1]) / 2, (b[0][2] + b[1][2]) / 2});
    }
  } catch (const voxfield::InvalidArgument& e) {
    std::abort();  // validate() refused what a reader accepted
  } catch (const voxfield::Error&) {
  }
  return 0;
}
