// voxfield — a slab of sample planes meshed in Flying Edges' passes (mesh_slab.h).
//
// The slab's planes stand in for a lattice of their own, meshed by FlyingEdges or FlyingDual with
// their offset in the whole one: positions, sources and messages in the whole lattice's frame.
// Marching cubes counts every plane it holds and writes the rows of [z_begin, z_end] (those of
// z_end for their vertices alone), each with the gradient stencils it has in the whole lattice.
// The dual meshers count and write only the cell planes [z_begin - 1, z_end) and the quads of
// sample planes [z_begin, z_end), with the whole lattice's rules at its faces; the vertices of
// cell plane z_begin - 1, numbered first by the passes, are moved behind the slab's own.
#include "voxfield/mesh_slab.h"

#include <algorithm>
#include <string>

#include "flying_edges.h"
#include "mesh_internal.h"
#include "voxfield/error.h"

namespace voxfield {

bool mesh_slab_applies(const MeshOptions& options) {
  return !options.value && !options.gradient;
}

std::pair<int, int> mesh_slab_planes(int samples_z, int z_begin, int z_end, Mesher mesher) {
  const int before = mesher == Mesher::kMarchingCubes ? 1 : 3;
  return {std::max(z_begin - before, 0), std::min(z_end + 3, samples_z)};
}

namespace {

// The dual meshers' slab: FlyingDual over the planes held, its first cell plane's vertices (the
// slab before's last) moved behind the slab's own.
MeshSlab dual_slab(const detail::mesh::Lattice& lattice, const MeshOptions& options, int w0,
                   int whole_z, int b, int e, std::vector<std::uint64_t>* sources) {
  using namespace detail::mesh;
  const FlyingDual passes(lattice, options, w0, whole_z, b, e);
  MeshSlab slab;
  slab.lent_from_before = true;
  const std::uint64_t lent = w0 + b > 0 ? passes.vertices_before(b) : 0;  // numbered first
  const std::uint64_t all = passes.vertices();
  slab.owned_vertices = all - lent;
  slab.last_plane_vertices = passes.vertices_before(e) - passes.vertices_before(e - 1);
  // (vertices_before(b) counts the plane before only: nothing is counted below it.)
  const WeldOutput out = size_mesh(slab.part, all, passes.indices(), false, sources);
  passes.write(out);
  Mesh& m = slab.part;
  const auto behind = [lent](auto& v) {
    std::rotate(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(lent), v.end());
  };
  behind(m.positions);
  behind(m.normals);
  if (sources) behind(*sources);
  const auto owned = static_cast<std::uint32_t>(slab.owned_vertices),
             first = static_cast<std::uint32_t>(lent);
  for (std::uint32_t& i : m.indices) i = i < first ? i + owned : i - first;
  return slab;
}

}  // namespace

MeshSlab mesh_slab(const ScalarVolume& frame, int planes_z0, int plane_count, const float* planes,
                   const MeshOptions& options, int z_begin, int z_end) {
  return detail::mesh::mesh_lattice_slab(frame, planes_z0, plane_count, planes, options, z_begin,
                                         z_end, false, nullptr);
}

namespace detail::mesh {

MeshSlab mesh_lattice_slab(const ScalarVolume& frame, int planes_z0, int plane_count,
                           const float* planes, const MeshOptions& options, int z_begin, int z_end,
                           bool voxel_faces, std::vector<std::uint64_t>* sources) {
  if (!mesh_slab_applies(options))
    throw InvalidArgument("mesh_slab: meshes without an analytic value or gradient");
  const int nz = frame.size.z;
  if (!(z_begin >= 0 && z_begin < z_end && z_end <= nz))
    throw InvalidArgument("mesh_slab: planes [" + std::to_string(z_begin) + ", " +
                          std::to_string(z_end) + ") are not a slab of the lattice's " +
                          std::to_string(nz));
  const auto [w0, w1] = mesh_slab_planes(nz, z_begin, z_end, options.algorithm);
  if (!planes || plane_count < 0 || planes_z0 > w0 ||
      static_cast<std::int64_t>(planes_z0) + plane_count < w1)
    throw InvalidArgument("mesh_slab: planes [" + std::to_string(z_begin) + ", " +
                          std::to_string(z_end) + ") read sample planes [" + std::to_string(w0) +
                          ", " + std::to_string(w1) + "), the slab holds [" +
                          std::to_string(planes_z0) + ", " +
                          std::to_string(static_cast<std::int64_t>(planes_z0) + plane_count) + ")");
  // The whole lattice's checks (its far corner, spacing, options), then its planes [w0, w1).
  ScalarVolume whole = frame;
  whole.values = planes;
  Lattice lattice = checked_lattice(whole, options, voxel_faces);
  const std::size_t plane = static_cast<std::size_t>(frame.size.x) * frame.size.y;
  lattice.n.z = w1 - w0;
  lattice.values = planes + plane * static_cast<std::size_t>(w0 - planes_z0);
  if (options.algorithm != Mesher::kMarchingCubes)
    return dual_slab(lattice, options, w0, nz, z_begin - w0, z_end - w0, sources);
  const FlyingEdges passes(lattice, options.interrupter, w0);
  // Local planes: the slab's own [b, e), plane z_end's rows up to v (their vertices only).
  const int b = z_begin - w0, e = z_end - w0, v = std::min(z_end + 1, nz) - w0;
  MeshSlab slab;
  slab.owned_vertices = passes.vertices_before(e) - passes.vertices_before(b);
  slab.first_plane_vertices = passes.vertices_before(b + 1) - passes.vertices_before(b);
  const WeldOutput out =
      size_mesh(slab.part, passes.vertices_before(v) - passes.vertices_before(b),
                passes.indices_before(e) - passes.indices_before(b), false, sources);
  passes.write_planes(b, v, e, out);
  return slab;
}

}  // namespace detail::mesh

}  // namespace voxfield
