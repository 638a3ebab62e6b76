// voxfield — a mesh piece's chunk parts, meshed or decoded from its bytes (internal to the mesh
// module; mesh_pieces.cpp holds both): for the weld that numbers one piece's share of the joined
// mesh (piece_weld.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "chunked_mesh.h"

namespace voxfield::detail::mesh {

struct PieceParts {
  Vec3i samples;
  int chunk_edge = 0;
  int first_layer = 0, end_layer = 0;
  std::vector<ChunkPart> parts;  // the layers' chunks, in chunk order
};

// mesh_piece's meshing, without the bytes (what it throws).
PieceParts mesh_piece_parts(const ScalarVolume& frame, int planes_z0, int plane_count,
                            const float* planes, const MeshOptions& options, int first_layer,
                            int end_layer);

// Checks the bytes as join_mesh_pieces does (InvalidArgument "<who>: piece <index> (byte N): why";
// ResourceLimitError past the memory limit).
PieceParts decode_piece(std::span<const std::uint8_t> piece, std::size_t index, const char* who);

}  // namespace voxfield::detail::mesh
