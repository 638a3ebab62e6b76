// voxfield — the weld that joins the chunks' parts into one indexed mesh (chunked_mesh.h explains
// the seams): owned vertices numbered chunk by chunk (a prefix sum), borrowed ones found by their
// element's key, orphans (a vertex no chunk owning it used) taken from their first user. Planned
// first — every count is known before anything is written — so the mesh can go straight into
// buffers a caller allocated, and a buffer too small is refused before any write.
#include <algorithm>
#include <limits>
#include <string>
#include <unordered_map>

#include "chunked_mesh.h"
#include "mesh_memory.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield::detail::mesh {

namespace {
constexpr std::uint32_t kUnresolved = std::numeric_limits<std::uint32_t>::max();
}

WeldPlan plan_weld(const std::vector<ChunkPart>& parts) {
  WeldPlan plan;
  const std::size_t chunks = parts.size();
  plan.base.assign(chunks + 1, 0);
  plan.index_base.assign(chunks + 1, 0);
  std::size_t shared_count = 0;
  for (std::size_t c = 0; c < chunks; ++c) {
    std::uint64_t owned = 0;
    for (std::size_t i = 0; i < parts[c].owned.size(); ++i) {
      owned += parts[c].owned[i];
      shared_count += parts[c].shared[i];
    }
    plan.base[c + 1] = plan.base[c] + owned;
    plan.index_base[c + 1] = plan.index_base[c] + parts[c].indices.size();
    plan.colored |= !parts[c].colors.empty();
  }
  if (plan.base.back() > kUnresolved - 1)
    throw InvalidArgument("mesh: " + std::to_string(plan.base.back()) +
                          " vertices do not fit 32-bit indices; mesh a smaller volume");
  std::unordered_map<std::uint64_t, std::uint32_t> by_key;
  by_key.reserve(shared_count);
  for (std::size_t c = 0; c < chunks; ++c) {
    const ChunkPart& p = parts[c];
    std::uint64_t next = plan.base[c];
    for (std::size_t i = 0; i < p.positions.size(); ++i) {
      if (!p.owned[i]) continue;
      if (p.shared[i]) by_key.emplace(p.keys[i], static_cast<std::uint32_t>(next));
      ++next;
    }
  }
  // Each chunk's numbering to the global one, chunks in parallel (the map is only read).
  plan.global.resize(chunks);
  parallel_for(chunks, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) {
      const ChunkPart& p = parts[c];
      plan.global[c].resize(p.positions.size());
      std::uint64_t next = plan.base[c];
      for (std::size_t i = 0; i < p.positions.size(); ++i) {
        if (p.owned[i]) {
          plan.global[c][i] = static_cast<std::uint32_t>(next++);
        } else {
          const auto it = by_key.find(p.keys[i]);
          plan.global[c][i] = it == by_key.end() ? kUnresolved : it->second;
        }
      }
    }
  });
  // A vertex its owner never used (surface nets: a cell only a neighbour's quads reach) is taken
  // from the first chunk that uses it; every chunk computes it bit for bit the same.
  std::uint64_t next = plan.base.back();
  for (std::size_t c = 0; c < chunks; ++c) {
    const ChunkPart& p = parts[c];
    for (std::size_t i = 0; i < p.positions.size(); ++i) {
      if (plan.global[c][i] != kUnresolved) continue;
      const auto [it, orphan] = by_key.emplace(p.keys[i], static_cast<std::uint32_t>(next));
      if (orphan) {
        if (next >= kUnresolved)
          throw InvalidArgument(
              "mesh: the vertices do not fit 32-bit indices; mesh a smaller volume");
        plan.orphans.push_back({static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(i)});
        ++next;
      }
      plan.global[c][i] = it->second;
    }
  }
  plan.vertices = next;
  plan.indices = plan.index_base.back();
  return plan;
}

void write_weld(const WeldPlan& plan, const std::vector<ChunkPart>& parts, const WeldOutput& out) {
  const std::size_t chunks = parts.size();
  parallel_for(chunks, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t c = begin; c < end; ++c) {
      const ChunkPart& p = parts[c];
      for (std::size_t i = 0; i < p.positions.size(); ++i) {
        if (!p.owned[i]) continue;
        const std::uint32_t g = plan.global[c][i];
        out.positions[g] = p.positions[i];
        out.normals[g] = p.normals[i];
        // (Parts meshed from one lattice all have colours or none: MeshChunks refuses updates from
        // another kind of source. Black, never a read past the array, if that ever broke.)
        if (out.colors)
          out.colors[g] = i < p.colors.size() ? p.colors[i] : std::array<std::uint8_t, 3>{};
        if (out.sources) out.sources[g] = p.sources[i];
      }
      std::uint32_t* indices = out.indices + plan.index_base[c];
      for (const std::uint32_t local : p.indices) *indices++ = plan.global[c][local];
    }
  });
  std::uint64_t g = plan.base.back();
  for (const auto& [c, i] : plan.orphans) {
    const ChunkPart& p = parts[c];
    out.positions[g] = p.positions[i];
    out.normals[g] = p.normals[i];
    if (out.colors)
      out.colors[g] = i < p.colors.size() ? p.colors[i] : std::array<std::uint8_t, 3>{};
    if (out.sources) out.sources[g] = p.sources[i];
    ++g;
  }
}

WeldOutput size_mesh(Mesh& mesh, std::uint64_t vertices, std::uint64_t indices, bool colored,
                     std::vector<std::uint64_t>* sources) {
  const std::uint64_t per_vertex = 2 * sizeof(std::array<float, 3>) +
                                   (colored ? sizeof(std::array<std::uint8_t, 3>) : 0) +
                                   (sources ? sizeof(std::uint64_t) : 0);
  require_memory(add_sat(mul_sat(vertices, per_vertex), mul_sat(indices, 4)), 0, "mesh",
                 "a mesh of " + std::to_string(vertices) + " vertices and " +
                     std::to_string(indices / 3) + " triangles");
  resize_on_huge_pages(mesh.positions, vertices);
  resize_on_huge_pages(mesh.normals, vertices);
  if (colored) resize_on_huge_pages(mesh.colors, vertices);
  resize_on_huge_pages(mesh.indices, indices);
  if (sources) resize_on_huge_pages(*sources, vertices);
  return {mesh.positions.data(), mesh.normals.data(), colored ? mesh.colors.data() : nullptr,
          mesh.indices.data(), sources ? sources->data() : nullptr};
}

Mesh weld(const std::vector<ChunkPart>& parts, std::vector<std::uint64_t>* sources) {
  const WeldPlan plan = plan_weld(parts);
  Mesh mesh;
  write_weld(plan, parts, size_mesh(mesh, plan.vertices, plan.indices, plan.colored, sources));
  return mesh;
}

}  // namespace voxfield::detail::mesh
