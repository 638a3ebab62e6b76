// voxfield — meshing a World through its exact signed distance field (mesh.h): at iso 0 the
// voxels' surface, at other iso values the offset surfaces of the metric.
//
// The field is computed on the content grown past the surface (so the surface closes in air, also
// where the content touches a bounded world's bounds: beyond them is air), clamped at |iso| + 3
// voxels: meshers read only the signs of neighbouring samples, their crossings and central
// differences, all within two voxels of the surface, where the clamped field is exact.
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "mesh_internal.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {

Mesh mesh_world(const World& world, const MeshOptions& options, Metric metric) {
  const double iso = options.iso;
  if (!(std::abs(iso) <= 1000))
    throw InvalidArgument("mesh: the iso value of a world (" + std::to_string(iso) +
                          " voxels) must be finite and within ±1000");
  const Box3i content = world.voxels.content_bounds();
  if (content.empty()) return Mesh{};
  // The surface lies up to iso voxels out: the domain reaches two voxels past it.
  const Box3i domain =
      content.grown(1 + static_cast<int>(std::ceil(std::max(iso, 0.0))) + (iso > 0 ? 1 : 0));
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
  field_options.metric = metric;
  field_options.signed_distance = true;
  field_options.max_distance = std::abs(iso) + 3;
  field_options.domain = domain;
  // An offset surface's vertices come from air samples: their colour is their nearest voxel's.
  field_options.nearest_sites = iso > 0;
  const DistanceField field = compute_distance_field(source, field_options);
  std::vector<float> samples(static_cast<std::size_t>(domain.volume()));
  std::get<Grid<float>>(field.values).copy_to_dense(domain, samples.data());

  ScalarVolume volume;
  volume.size = size;
  volume.values = samples.data();
  for (int a = 0; a < 3; ++a)
    volume.origin_units[static_cast<std::size_t>(a)] = domain.begin[a] + 0.5;
  MeshOptions o = options;
  o.inside_above = false;
  std::vector<std::uint64_t> sources;
  Mesh mesh = detail::mesh::mesh_lattice(volume, o, &sources, /*voxel_faces=*/iso == 0);
  mesh.colors.resize(mesh.positions.size());
  const std::uint64_t nx = static_cast<std::uint64_t>(size.x),
                      nxy = nx * static_cast<std::uint64_t>(size.y);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const std::uint64_t s = sources[i];
    const Vec3i p{domain.begin.x + static_cast<int>(s % nx),
                  domain.begin.y + static_cast<int>(s / nx % static_cast<std::uint64_t>(size.y)),
                  domain.begin.z + static_cast<int>(s / nxy)};
    std::uint8_t material = world.voxels.get(p);
    if (material == 0 && field.sites) {  // an air sample of an offset surface: its nearest voxel
      const SiteOffset off = field.sites->get(p);
      if (!off.none()) material = world.voxels.get({p.x + off.dx, p.y + off.dy, p.z + off.dz});
    }
    const Rgba c = world.palette[material];
    mesh.colors[i] = {c.r, c.g, c.b};
  }
  return mesh;
}

}  // namespace voxfield
