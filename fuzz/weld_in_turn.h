// voxfield fuzz harnesses and tests — PieceWeld's protocol (mesh_pieces.h) run in one process over
// pieces of consecutive runs of layers, as the ranks of an MPI job run it: each piece learns only
// from its neighbours, and the shares are assembled into one mesh by their global numbers (the test
// and fuzz harnesses compare it with join_mesh_pieces). Throws what PieceWeld throws, and
// voxfield::InvalidArgument when a share numbers a vertex outside the mesh.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/mesh_pieces.h"

namespace voxfield::test {

inline Mesh weld_in_turn(const std::vector<std::span<const std::uint8_t>>& pieces) {
  std::vector<PieceWeld> welds;
  for (const auto& p : pieces) welds.emplace_back(p);
  const std::size_t n = welds.size();
  std::uint64_t owned = 0;
  std::vector<std::vector<WeldKey>> lent(n);
  for (std::size_t i = 0; i < n; ++i) {
    lent[i] = welds[i].lend(owned);
    owned += welds[i].owned_vertices();
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) welds[i].borrow(lent[i - 1]);
    if (i + 1 < n) welds[i].borrow(lent[i + 1]);
  }
  std::vector<std::vector<std::uint64_t>> orphan_keys(n);
  for (std::size_t i = 0; i < n; ++i) orphan_keys[i] = welds[i].orphan_keys();
  std::uint64_t next = owned;
  for (std::size_t i = 0; i < n; ++i) {
    welds[i].claim_orphans(i > 0 ? std::span<const std::uint64_t>(orphan_keys[i - 1])
                                 : std::span<const std::uint64_t>());
    const std::vector<WeldKey> numbered = welds[i].number_orphans(next);
    next += welds[i].claimed_orphans();
    if (i + 1 < n) welds[i + 1].borrow(numbered);
  }
  Mesh mesh;
  mesh.positions.resize(next);
  mesh.normals.resize(next);
  for (const PieceWeld& w : welds) {
    const Mesh part = w.part();
    const std::vector<std::uint32_t> global = w.global();
    if (!part.colors.empty()) mesh.colors.resize(next);
    for (std::size_t v = 0; v < part.vertex_count(); ++v) {
      if (global[v] >= next) throw InvalidArgument("weld_in_turn: a number past the mesh");
      mesh.positions[global[v]] = part.positions[v];
      mesh.normals[global[v]] = part.normals[v];
      if (!part.colors.empty()) mesh.colors[global[v]] = part.colors[v];
    }
    for (const std::uint32_t i : part.indices) mesh.indices.push_back(global[i]);
  }
  return mesh;
}

}  // namespace voxfield::test
