// voxfield — meshing a World through its exact signed Euclidean distance field.
//
// The field is computed on the content grown by one voxel (so the surface closes in air, also where
// the content touches a bounded world's bounds: beyond them is air), clamped
// at 3 voxels: meshers read only the signs of neighbouring samples, their crossings and central
// differences, all within two voxels of the surface, where the clamped field is exact.
#include <optional>
#include <vector>

#include "mesh_internal.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {

Mesh mesh_world(const World& world, const MeshOptions& options) {
  const Box3i content = world.voxels.content_bounds();
  if (content.empty()) return Mesh{};
  const Box3i domain = content.grown(1);
  const Vec3i size = domain.size();
  // Voxels beyond a bounded world's bounds are air: where the grown content leaves the bounds, the
  // field is computed on an unbounded copy so that the surface closes there with exact distances.
  const bool clipped = world.voxels.bounds() && domain.intersect(*world.voxels.bounds()) != domain;
  std::optional<World> unbounded;
  if (clipped) {
    unbounded.emplace(world.voxels.chunk_edge());
    unbounded->voxels = world.voxels.rechunked(world.voxels.chunk_edge(), std::nullopt);
  }
  const World& source = clipped ? *unbounded : world;
  // The float samples: 4 bytes per voxel of the domain, on top of the field itself.
  require_memory(mul_sat(static_cast<std::uint64_t>(domain.volume()), 8), 0, "mesh",
                 "the world's signed distance samples");
  DistanceOptions field_options;
  field_options.metric = Metric::kEuclidean;
  field_options.signed_distance = true;
  field_options.max_distance = 3;
  field_options.domain = domain;
  const DistanceField field = compute_distance_field(source, field_options);
  std::vector<float> samples(static_cast<std::size_t>(domain.volume()));
  std::get<Grid<float>>(field.values).copy_to_dense(domain, samples.data());

  ScalarVolume volume;
  volume.size = size;
  volume.values = samples.data();
  for (int a = 0; a < 3; ++a)
    volume.origin_units[static_cast<std::size_t>(a)] = domain.begin[a] + 0.5;
  MeshOptions o = options;
  o.iso = 0;
  o.inside_above = false;
  std::vector<std::uint64_t> sources;
  Mesh mesh = detail::mesh::mesh_lattice(volume, o, &sources, /*voxel_faces=*/true);
  mesh.colors.resize(mesh.positions.size());
  const std::uint64_t nx = static_cast<std::uint64_t>(size.x),
                      nxy = nx * static_cast<std::uint64_t>(size.y);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const std::uint64_t s = sources[i];
    const Vec3i p{domain.begin.x + static_cast<int>(s % nx),
                  domain.begin.y + static_cast<int>(s / nx % static_cast<std::uint64_t>(size.y)),
                  domain.begin.z + static_cast<int>(s / nxy)};
    const Rgba c = world.palette[world.voxels.get(p)];
    mesh.colors[i] = {c.r, c.g, c.b};
  }
  return mesh;
}

}  // namespace voxfield
