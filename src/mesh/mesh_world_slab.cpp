// voxfield — a slab of a voxel world's surface (mesh_slab.h: mesh_world_slab), for programs that
// hold only some z-slices of a world (the ranks of voxfield-mpi mesh).
//
// mesh_world meshes the world's exact signed field over its lattice, clamped at 3 voxels
// (world_field_options): a clamped value depends only on the voxels within the clamp of it
// (docs/distance.md, "Exactness with a clamp"). So the samples of the planes a slab reads are the
// field of the lattice cut to those planes grown by the clamp along z — the same values, bit for
// bit, as mesh_world's field there — and meshing them as a slab of the lattice with voxel faces
// (mesh_lattice_slab) gives mesh_world's rows. Colours and the frame follow as in mesh_world.
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "mesh_internal.h"
#include "voxfield/distance.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_slab.h"

namespace voxfield {

namespace {

// The field's clamp at iso 0 (world_field_options: |iso| + 3), in whole slices.
int clamp_slices() {
  return static_cast<int>(
      std::ceil(detail::mesh::world_field_options(0, Metric::kEuclidean, Box3i{}).max_distance));
}

}  // namespace

std::pair<int, int> mesh_world_slab_voxels(const Box3i& lattice, int z_begin, int z_end,
                                           Mesher mesher) {
  const auto [w0, w1] = mesh_slab_planes(lattice.size().z, z_begin, z_end, mesher);
  return {std::max(lattice.begin.z, lattice.begin.z + w0 - clamp_slices()),
          std::min(lattice.end.z, lattice.begin.z + w1 + clamp_slices())};
}

int mesh_world_slab_reach(Mesher mesher) {
  // mesh_slab_planes' planes before and after a slab, on a lattice too deep to cut them.
  constexpr int kDeep = 1 << 20, kAt = 1 << 19;
  const auto [w0, w1] = mesh_slab_planes(kDeep, kAt, kAt + 1, mesher);
  return std::max(kAt - w0, w1 - (kAt + 1)) + clamp_slices();
}

MeshSlab mesh_world_slab(const World& world, const Box3i& lattice, const MeshOptions& options,
                         Metric metric, int z_begin, int z_end) {
  using namespace detail::mesh;
  if (options.iso != 0)
    throw InvalidArgument(
        "mesh_world_slab: a slab of a world's surface is meshed at iso 0 (an offset surface's "
        "normals and colours come from the nearest voxels, which may lie in any slab)");
  if (!mesh_slab_applies(options))
    throw InvalidArgument("mesh_world_slab: meshes without an analytic value or gradient");
  const Vec3i size = lattice.size();
  if (size.x < 2 || size.y < 2 || size.z < 2)
    throw InvalidArgument("mesh_world_slab: the lattice " + to_string(lattice) +
                          " needs at least 2 samples along each axis");
  if (!(z_begin >= 0 && z_begin < z_end && z_end <= size.z))
    throw InvalidArgument("mesh_world_slab: planes [" + std::to_string(z_begin) + ", " +
                          std::to_string(z_end) + ") are not a slab of the lattice's " +
                          std::to_string(size.z));
  const auto [w0, w1] = mesh_slab_planes(size.z, z_begin, z_end, options.algorithm);
  const auto [v0, v1] = mesh_world_slab_voxels(lattice, z_begin, z_end, options.algorithm);
  Box3i field_box = lattice;
  field_box.begin.z = v0;
  field_box.end.z = v1;
  // Beyond a bounded world's bounds is air: where the box leaves them, an unbounded copy (as
  // mesh_world does).
  const bool clipped =
      world.voxels.bounds() && field_box.intersect(*world.voxels.bounds()) != field_box;
  std::optional<World> unbounded;
  if (clipped) {
    unbounded.emplace(world.voxels.chunk_edge());
    unbounded->voxels = world.voxels.rechunked(world.voxels.chunk_edge(), std::nullopt);
  }
  const World& source = clipped ? *unbounded : world;
  Box3i planes_box = lattice;
  planes_box.begin.z = lattice.begin.z + w0;
  planes_box.end.z = lattice.begin.z + w1;
  require_memory(add_sat(mul_sat(static_cast<std::uint64_t>(field_box.volume()), 4),
                         mul_sat(static_cast<std::uint64_t>(planes_box.volume()), 4)),
                 0, "mesh", "the world's signed distance samples");
  const DistanceField field =
      compute_distance_field(source, world_field_options(0, metric, field_box));
  std::vector<float> samples(static_cast<std::size_t>(planes_box.volume()));
  std::get<Grid<float>>(field.values).copy_to_dense(planes_box, samples.data());

  const ScalarVolume frame = world_lattice_frame(lattice);
  MeshOptions o = options;
  o.inside_above = false;
  std::vector<std::uint64_t> sources;
  MeshSlab slab = mesh_lattice_slab(frame, w0, w1 - w0, samples.data(), o, z_begin, z_end,
                                    /*voxel_faces=*/true, &sources);
  color_by_sources(world, field, lattice, sources, slab.part);
  place_in_frame(slab.part, world.frame);
  return slab;
}

}  // namespace voxfield
