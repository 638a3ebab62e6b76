// libFuzzer harness for join_mesh_pieces (mesh_pieces.h): the bytes a rank of voxfield-mpi mesh
// sends rank 0. Random bytes would never get past a piece's header, so the harness starts from the
// real pieces of a small lattice — layers [0, 1) and [1, 3), every mesher by turns — and reads the
// input as damage to them: its first byte picks the mesher, the next two cut the second piece to a
// length, then each three bytes set one byte of either piece at an offset. Any input must join or
// throw voxfield::Error; a mesh that joins must index only its own vertices. The same pieces are
// welded share by share too (PieceWeld, as the ranks of voxfield-mpi mesh weld them), with the
// same contract.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "fuzz_common.h"
#include "voxfield/error.h"
#include "voxfield/mesh_pieces.h"
#include "weld_in_turn.h"

namespace {

// Pieces [0, 1) and [1, 3) of a 9 x 8 x 13 lattice cut in chunks of 4 cells, for mesher m.
std::array<std::vector<std::uint8_t>, 2> real_pieces(voxfield::Mesher m) {
  using namespace voxfield;
  const Vec3i n{9, 8, 13};
  std::vector<float> v(static_cast<std::size_t>(n.x) * n.y * n.z);
  std::size_t i = 0;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x, ++i)
        v[i] = static_cast<float>(std::sin(0.9 * x + 0.3 * z) + std::cos(0.7 * y - 0.5 * z) - 0.2);
  MeshOptions o;
  o.algorithm = m;
  o.chunk_edge = 4;
  const ScalarVolume frame{n, nullptr};
  return {mesh_piece(frame, 0, n.z, v.data(), o, 0, 1),
          mesh_piece(frame, 0, n.z, v.data(), o, 1, 3)};
}

std::array<std::array<std::vector<std::uint8_t>, 2>, 3> pieces;

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  voxfield::fuzz::init_limits();
  pieces = {real_pieces(voxfield::Mesher::kMarchingCubes),
            real_pieces(voxfield::Mesher::kSurfaceNets),
            real_pieces(voxfield::Mesher::kDualContouring)};
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 3) return 0;
  const auto& real = pieces[data[0] % 3];
  std::array<std::vector<std::uint8_t>, 2> piece = real;
  const std::size_t keep =
      (static_cast<std::size_t>(data[1]) << 8 | data[2]) % (piece[1].size() + 1);
  piece[1].resize(keep == 0 ? piece[1].size() : keep);  // 0 keeps it whole
  // Each edit: the top bit picks the piece (both can be forged, headers that agree included).
  for (std::size_t at = 3; at + 3 <= size; at += 3) {
    std::vector<std::uint8_t>& p = piece[data[at] >> 7];
    if (p.empty()) continue;
    const std::size_t offset =
        (static_cast<std::size_t>(data[at] & 0x7f) << 8 | data[at + 1]) % p.size();
    p[offset] = data[at + 2];
  }
  const std::vector<std::span<const std::uint8_t>> spans{std::span<const std::uint8_t>(piece[0]),
                                                         std::span<const std::uint8_t>(piece[1])};
  try {
    const voxfield::Mesh mesh = voxfield::join_mesh_pieces(spans);
    for (const std::uint32_t index : mesh.indices)
      if (index >= mesh.vertex_count()) std::abort();
  } catch (const voxfield::Error&) {
  }
  try {
    const voxfield::Mesh mesh = voxfield::test::weld_in_turn(spans);
    for (const std::uint32_t index : mesh.indices)
      if (index >= mesh.vertex_count()) std::abort();
  } catch (const voxfield::Error&) {
  }
  return 0;
}
