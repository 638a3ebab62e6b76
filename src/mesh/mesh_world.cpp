// voxfield — meshing a World through its exact signed distance field (mesh.h): at iso 0 the
// voxels' surface, at other iso values the offset surfaces of the metric.
//
// The field is computed on the content grown past the surface (so the surface closes in air, also
// where the content touches a bounded world's bounds: beyond them is air), clamped at |iso| + 3
// voxels: meshers read only the signs of neighbouring samples, their crossings and central
// differences, all within two voxels of the surface, where the clamped field is exact.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "mesh_internal.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {

namespace detail::mesh {

// The exact gradient of a world's signed field at a point of an offset surface, from the field's
// nearest sites: Hermite data for dual contouring, and every mesher's normals. Outside (iso > 0)
// the field is the distance to the nearest solid voxel centre c, whose gradient is (p - c) / |p -
// c| (Euclidean), the unit axis of the largest |p - c| component (Chebyshev), or the signs of p - c
// (Manhattan); inside it is minus the distance to the nearest air voxel centre. The nearest centre
// of p is taken among the candidates of the cell around it: each corner sample of the kind the
// distance is measured to is its own candidate, each of the other kind offers its nearest site.
std::function<std::array<double, 3>(const std::array<double, 3>&)> offset_gradient(
    const World& world, const DistanceField& field, Metric metric, bool outside) {
  return [&world, &field, metric, outside](const std::array<double, 3>& p) {
    const Box3i& domain = field.domain;
    Vec3i base;
    for (int a = 0; a < 3; ++a)
      base[a] = std::clamp(static_cast<int>(std::floor(p[static_cast<std::size_t>(a)] - 0.5)),
                           domain.begin[a], domain.end[a] - 2);
    const Vec3d at{p[0], p[1], p[2]};
    auto metric_length = [metric](const Vec3d& d) {
      if (metric == Metric::kManhattan) return std::abs(d.x) + std::abs(d.y) + std::abs(d.z);
      if (metric == Metric::kChebyshev)
        return std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
      return d.length();
    };
    bool found = false;
    Vec3d best_centre;
    double best = std::numeric_limits<double>::infinity();
    for (int c = 0; c < 8; ++c) {
      const Vec3i q{base.x + (c & 1), base.y + (c >> 1 & 1), base.z + (c >> 2 & 1)};
      // A sample of the kind the distance is measured to is its own site; another one's site is
      // its nearest voxel of that kind.
      Vec3i site = q;
      if ((world.voxels.get(q) != 0) == outside) {
        // q is of the measured kind (solid outside, air inside): itself.
      } else {
        const SiteOffset off = field.sites->get(q);
        if (off.none()) continue;
        site = {q.x + off.dx, q.y + off.dy, q.z + off.dz};
      }
      const Vec3d centre{site.x + 0.5, site.y + 0.5, site.z + 0.5};
      const double d = metric_length(at - centre);
      if (d < best) best = d, best_centre = centre, found = true;
    }
    std::array<double, 3> g{0, 0, 0};
    if (!found) return g;  // no site in reach: zero, which the meshers' fallbacks handle
    const Vec3d d = at - best_centre;
    if (metric == Metric::kEuclidean) {
      const double l = d.length();
      if (l > 0) g = {d.x / l, d.y / l, d.z / l};
    } else if (metric == Metric::kChebyshev) {
      int axis = 0;
      for (int a = 1; a < 3; ++a)
        if (std::abs(d[a]) > std::abs(d[axis])) axis = a;
      g[static_cast<std::size_t>(axis)] = d[axis] > 0 ? 1 : d[axis] < 0 ? -1 : 0;
    } else {
      for (int a = 0; a < 3; ++a) g[static_cast<std::size_t>(a)] = d[a] > 0 ? 1 : d[a] < 0 ? -1 : 0;
    }
    if (!outside)
      for (double& v : g) v = -v;
    return g;
  };
}

int world_surface_margin(double iso) {
  if (!(std::abs(iso) <= 1000))
    throw InvalidArgument("mesh: the iso value of a world (" + std::to_string(iso) +
                          " voxels) must be finite and within ±1000");
  // Between a solid and an air centre the field steps from -1 to +1: a level in (-1, 1) other
  // than 0 would land between them, not at its distance from either.
  if (iso != 0 && std::abs(iso) < 1)
    throw InvalidArgument("mesh: a world's offset surface is at least 1 voxel out (or in); iso " +
                          std::to_string(iso) + " lies between neighbouring voxel centres");
  // The surface lies up to iso voxels out: the domain reaches two voxels past it. At iso 0 the
  // first air sample past the voxels' surface is a corner of the cells the surface crosses, and
  // its central difference reads one more: so two samples of air, or the normals there would
  // turn one-sided where the content ends — unlike the same surface elsewhere (and unlike a
  // WorldMeshChunks, whose lattice ends at the bounds, not the content).
  if (iso == 0) return 2;
  return 1 + static_cast<int>(std::ceil(std::max(iso, 0.0))) + (iso > 0 ? 1 : 0);
}

DistanceOptions world_field_options(double iso, Metric metric, const Box3i& domain) {
  DistanceOptions o;
  o.metric = metric;
  o.signed_distance = true;
  o.max_distance = std::abs(iso) + 3;
  o.domain = domain;
  // An offset surface's normals come from the nearest sites (offset_gradient), and its vertices
  // from air samples take their colour from their nearest voxel.
  o.nearest_sites = iso != 0;
  return o;
}

ScalarVolume world_lattice_frame(const Box3i& domain) {
  ScalarVolume volume;
  volume.size = domain.size();
  for (int a = 0; a < 3; ++a)
    volume.origin_units[static_cast<std::size_t>(a)] = domain.begin[a] + 0.5;
  return volume;
}

std::uint8_t world_vertex_material(const World& world, const DistanceField& field, Vec3i p) {
  std::uint8_t material = world.voxels.get(p);
  if (material == 0 && field.sites) {  // an air sample of an offset surface: its nearest voxel
    const SiteOffset off = field.sites->get(p);
    if (!off.none()) material = world.voxels.get({p.x + off.dx, p.y + off.dy, p.z + off.dz});
  }
  return material;
}

void color_by_sources(const World& world, const DistanceField& field, const Box3i& lattice,
                      const std::vector<std::uint64_t>& sources, Mesh& mesh) {
  mesh.colors.resize(mesh.positions.size());
  const Vec3i size = lattice.size();
  const std::uint64_t nx = static_cast<std::uint64_t>(size.x),
                      nxy = nx * static_cast<std::uint64_t>(size.y);
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const std::uint64_t s = sources[i];
    const Vec3i p{lattice.begin.x + static_cast<int>(s % nx),
                  lattice.begin.y + static_cast<int>(s / nx % static_cast<std::uint64_t>(size.y)),
                  lattice.begin.z + static_cast<int>(s / nxy)};
    const Rgba c = world.palette[world_vertex_material(world, field, p)];
    mesh.colors[i] = {c.r, c.g, c.b};
  }
}

}  // namespace detail::mesh

int mesh_world_margin(double iso) {
  return detail::mesh::world_surface_margin(iso);
}

Mesh mesh_world(const World& world, const MeshOptions& options, Metric metric) {
  using namespace detail::mesh;
  const double iso = options.iso;
  const int margin = world_surface_margin(iso);
  const Box3i content = world.voxels.content_bounds();
  if (content.empty()) return Mesh{};
  const Box3i domain = content.grown(margin);
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
  const DistanceField field =
      compute_distance_field(source, world_field_options(iso, metric, domain));
  std::vector<float> samples(static_cast<std::size_t>(domain.volume()));
  std::get<Grid<float>>(field.values).copy_to_dense(domain, samples.data());

  ScalarVolume volume = world_lattice_frame(domain);
  volume.values = samples.data();
  MeshOptions o = options;
  o.inside_above = false;
  if (iso != 0) o.gradient = offset_gradient(source, field, metric, iso > 0);
  std::vector<std::uint64_t> sources;
  Mesh mesh = mesh_lattice(volume, o, &sources, /*voxel_faces=*/iso == 0);
  color_by_sources(world, field, domain, sources, mesh);
  place_in_frame(mesh, world.frame);
  return mesh;
}

void place_in_frame(Mesh& mesh, const VoxelFrame& frame) {
  if (frame.is_identity()) return;
  frame.validate("mesh: the world's frame");
  // Per vertex in doubles, rounded once to float: a frame far from the origin (a scan's
  // millimetres, a map's metres) keeps what float positions can hold.
  auto to_float = [](Vec3d v) {
    return std::array<float, 3>{static_cast<float>(v.x), static_cast<float>(v.y),
                                static_cast<float>(v.z)};
  };
  for (auto& p : mesh.positions) p = to_float(frame.world_from_vox({p[0], p[1], p[2]}));
  for (auto& n : mesh.normals) n = to_float(frame.world_normal({n[0], n[1], n[2]}));
}

}  // namespace voxfield
