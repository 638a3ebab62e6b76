// voxfield — caller-allocated mesh outputs (mesh.h): the worst-case sizes of each mesher's output
// on a lattice, and meshing straight into arrays the caller owns (the weld is planned first, so a
// buffer too small is refused before anything is written).
#include <algorithm>
#include <bit>
#include <string>

#include "cube_cases.h"
#include "flying_edges.h"
#include "mesh_internal.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/terrain.h"

namespace voxfield {

MeshBound mesh_bound(Vec3i samples, Mesher algorithm) {
  for (int a = 0; a < 3; ++a)
    if (samples[a] < 2)
      throw InvalidArgument("mesh_bound: a lattice needs at least 2 samples along each axis (" +
                            to_string(samples) + ")");
  const auto nx = static_cast<std::uint64_t>(samples.x), ny = static_cast<std::uint64_t>(samples.y),
             nz = static_cast<std::uint64_t>(samples.z);
  // Saturating: a lattice whose counts pass 64 bits gets a bound no buffer can meet, never a
  // small wrapped one.
  const std::uint64_t edges =
      add_sat(add_sat(mul_sat(mul_sat(nx - 1, ny), nz), mul_sat(mul_sat(nx, ny - 1), nz)),
              mul_sat(mul_sat(nx, ny), nz - 1));
  const std::uint64_t cells = mul_sat(mul_sat(nx - 1, ny - 1), nz - 1);
  MeshBound b;
  if (algorithm == Mesher::kMarchingCubes) {
    // The table's largest case, in triangles and centre vertices, over every corner mask and
    // every decision of its ambiguous faces.
    const auto& cases = detail::mesh::CubeCases::get();
    std::uint64_t triangles = 0, centres = 0;
    for (unsigned inside = 0; inside < 256; ++inside) {
      const unsigned ambiguous =
          static_cast<unsigned>(std::popcount(cases.ambiguous_faces(inside)));
      for (unsigned joined = 0; joined < (1u << ambiguous); ++joined) {
        const auto& c = cases.lookup(inside, joined);
        triangles = std::max<std::uint64_t>(triangles, c.triangle_count);
        centres = std::max<std::uint64_t>(centres, c.centre_count);
      }
    }
    b.vertices = add_sat(edges, mul_sat(centres, cells));
    b.indices = mul_sat(3 * triangles, cells);
  } else {
    b.vertices = cells;
    b.indices = mul_sat(6, edges);
  }
  return b;
}

namespace detail::mesh {
namespace {

// Refuses buffers smaller than the mesh, before anything is written.
void check_room(std::size_t vertices, std::size_t indices, bool colors, const MeshBuffers& out) {
  if (out.positions.size() < vertices || out.normals.size() < vertices ||
      (colors && out.colors.size() < vertices) || out.indices.size() < indices)
    throw InvalidArgument("mesh: the mesh needs " + std::to_string(vertices) +
                          " positions and normals" + (colors ? " and colours" : "") + " and " +
                          std::to_string(indices) + " indices; the buffers hold " +
                          std::to_string(out.positions.size()) + ", " +
                          std::to_string(out.normals.size()) +
                          (colors ? ", " + std::to_string(out.colors.size()) : "") + " and " +
                          std::to_string(out.indices.size()) + " (size them with mesh_bound)");
}

MeshCounts write_into(const std::vector<ChunkPart>& parts, const MeshBuffers& out) {
  const WeldPlan plan = plan_weld(parts);
  const bool colors = plan.colored && !out.colors.empty();
  check_room(plan.vertices, plan.indices, colors, out);
  write_weld(plan, parts,
             {out.positions.data(), out.normals.data(), colors ? out.colors.data() : nullptr,
              out.indices.data(), nullptr});
  return {plan.vertices, plan.indices};
}

}  // namespace
}  // namespace detail::mesh

MeshCounts mesh_volume_into(const ScalarVolume& volume, const MeshOptions& options,
                            const MeshBuffers& out) {
  using namespace detail::mesh;
  const Lattice lattice = checked_lattice(volume, options, false);
  const auto into = [&](const auto& plan) -> MeshCounts {
    check_room(plan.vertices(), plan.indices(), false, out);
    plan.write({out.positions.data(), out.normals.data(), nullptr, out.indices.data(), nullptr});
    return {plan.vertices(), plan.indices()};
  };
  return mesh_by_plan(lattice, options, into,
                      [&] { return write_into(mesh_all_chunks(lattice, options), out); });
}

MeshCounts mesh_terrain_into(const TerrainField& terrain, const MeshOptions& options,
                             const MeshBuffers& out) {
  using namespace detail::mesh;
  const MeshOptions o = terrain_options(terrain, options);
  TerrainSamples keep;
  return write_into(mesh_all_chunks(terrain_lattice(terrain, o, keep), o), out);
}

}  // namespace voxfield
