// voxfield — meshing a sampled volume: checks the request, meshes the chunks in parallel on
// voxfield's pool and welds them (chunked_mesh.h).
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "chunked_mesh.h"
#include "flying_edges.h"
#include "mesh_internal.h"
#include "voxfield/error.h"
#include "voxfield/interrupt.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield {

const char* mesher_name(Mesher m) {
  switch (m) {
    case Mesher::kMarchingCubes:
      return "mc";
    case Mesher::kSurfaceNets:
      return "sn";
    case Mesher::kDualContouring:
      return "dc";
  }
  return "?";
}

Mesher parse_mesher(const std::string& name) {
  if (name == "mc" || name == "marching-cubes") return Mesher::kMarchingCubes;
  if (name == "sn" || name == "surface-nets") return Mesher::kSurfaceNets;
  if (name == "dc" || name == "dual-contouring") return Mesher::kDualContouring;
  throw InvalidArgument("unknown mesher '" + name + "' (expected mc, sn or dc)");
}

namespace detail::mesh {

Lattice checked_lattice(const ScalarVolume& volume, const MeshOptions& options, bool voxel_faces,
                        const std::function<void(const Box3i&, float*)>* fill) {
  if (!volume.values && !fill) throw InvalidArgument("mesh: the volume has no samples");
  for (int a = 0; a < 3; ++a) {
    if (volume.size[a] < 2)
      throw InvalidArgument("mesh: the volume needs at least 2 samples along each axis (it has " +
                            std::to_string(volume.size.x) + " x " + std::to_string(volume.size.y) +
                            " x " + std::to_string(volume.size.z) + ")");
    // Positions are floats: the spacing must be a normal float and the far corner representable.
    const double s = volume.spacing_units[static_cast<std::size_t>(a)];
    const double o = volume.origin_units[static_cast<std::size_t>(a)];
    const double far = o + (volume.size[a] - 1) * s;
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    if (!(s >= std::numeric_limits<float>::min()) || !(s <= kFloatMax))
      throw InvalidArgument("mesh: spacing must be positive and within float range");
    if (!(std::abs(o) <= kFloatMax) || !(std::abs(far) <= kFloatMax))
      throw InvalidArgument("mesh: the volume's origin and far corner must be finite floats");
  }
  if (!(std::abs(options.iso) <= std::numeric_limits<float>::max()))
    throw InvalidArgument("mesh: iso must be a finite float");
  if (options.chunk_edge < 2 || options.chunk_edge > 256)
    throw InvalidArgument("mesh: chunk edge " + std::to_string(options.chunk_edge) +
                          " is outside 2..256");
  Lattice lattice;
  lattice.n = volume.size;
  lattice.values = volume.values;
  lattice.fill = volume.values ? nullptr : fill;
  lattice.origin = volume.origin_units;
  lattice.spacing = volume.spacing_units;
  lattice.iso = options.iso;
  lattice.sign = options.inside_above ? -1 : 1;
  lattice.voxel_faces = voxel_faces;
  lattice.gradient = options.gradient ? &options.gradient : nullptr;
  lattice.value = options.value ? &options.value : nullptr;
  return lattice;
}

double Lattice::crossing(Vec3i p, int axis, double s0, double s1) const {
  double t = s0 / (s0 - s1);  // the signs differ, so s0 != s1
  if (!value) return t;
  // Illinois regula falsi on s(t) = sign * (value - iso) between the edge's ends, which bracket
  // the root; stops when the bracket is below 1e-9 of the edge.
  std::array<double, 3> a{origin[0] + p.x * spacing[0], origin[1] + p.y * spacing[1],
                          origin[2] + p.z * spacing[2]};
  const double start = a[static_cast<std::size_t>(axis)],
               length = spacing[static_cast<std::size_t>(axis)];
  double lo = 0, hi = 1, f_lo = s0, f_hi = s1;
  int side = 0;
  for (int it = 0; it < 60 && hi - lo > 1e-9; ++it) {
    a[static_cast<std::size_t>(axis)] = start + t * length;
    const double f = sign * ((*value)(a)-iso);
    if (f == 0) return t;
    if ((f < 0) == (f_lo < 0)) {
      lo = t, f_lo = f;
      if (side == -1) f_hi /= 2;
      side = -1;
    } else {
      hi = t, f_hi = f;
      if (side == 1) f_lo /= 2;
      side = 1;
    }
    t = lo + (hi - lo) * (f_lo / (f_lo - f_hi));
    if (!(t > lo && t < hi)) t = (lo + hi) / 2;
  }
  return t;
}

void mesh_chunks(const Lattice& lattice, const ChunkGrid& grid, const MeshOptions& options,
                 const std::vector<std::int64_t>& chunks, std::vector<ChunkPart>& parts) {
  Progress progress(options.interrupter,
                    options.algorithm == Mesher::kMarchingCubes ? "marching cubes"
                    : options.algorithm == Mesher::kSurfaceNets ? "surface nets"
                                                                : "dual contouring",
                    static_cast<std::int64_t>(chunks.size()));
  parallel_for(chunks.size(), 1, [&](std::size_t begin, std::size_t end) {
    Block block;
    std::vector<std::int32_t> scratch;
    for (std::size_t i = begin; i < end; ++i) {
      if (!progress.keep_going()) return;
      const Vec3i chunk = grid.coord(chunks[i]);
      ChunkPart& part = parts[i];
      part.clear();
      if (block.load(lattice, grid.cells_of(chunk))) {
        if (options.algorithm == Mesher::kMarchingCubes)
          marching_cubes_chunk(lattice, grid, chunk, block, scratch, part);
        else
          dual_grid_chunk(lattice, grid, chunk, block, scratch, part,
                          options.algorithm == Mesher::kSurfaceNets ? surface_nets_vertex
                                                                    : dual_contouring_vertex);
        if (lattice.color) {
          part.colors.resize(part.sources.size());
          for (std::size_t v = 0; v < part.sources.size(); ++v)
            part.colors[v] = (*lattice.color)(part.sources[v]);
        }
      }
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
}

namespace {

// A whole-volume plan's mesh in fresh arrays.
template <class Plan>
Mesh mesh_of(const Plan& plan, std::vector<std::uint64_t>* sources) {
  Mesh mesh;
  plan.write(size_mesh(mesh, plan.vertices(), plan.indices(), false, sources));
  return mesh;
}

}  // namespace

Mesh mesh_lattice(const ScalarVolume& volume, const MeshOptions& options,
                  std::vector<std::uint64_t>* sources, bool voxel_faces) {
  const Lattice lattice = checked_lattice(volume, options, voxel_faces);
  return mesh_by_plan(
      lattice, options, [&](const auto& plan) { return mesh_of(plan, sources); },
      [&] { return weld(mesh_all_chunks(lattice, options), sources); });
}

std::vector<ChunkPart> mesh_all_chunks(const Lattice& lattice, const MeshOptions& options) {
  const ChunkGrid grid(lattice.n, options.chunk_edge);
  // One part per chunk (bookkeeping even where there is no surface): refuse partitions whose
  // bookkeeping alone would pass the memory limit.
  require_memory(mul_sat(static_cast<std::uint64_t>(grid.total()), 256), 0, "mesh",
                 "chunks of " + std::to_string(options.chunk_edge) + " cells (" +
                     std::to_string(grid.total()) + " of them; choose a larger --chunk)");
  std::vector<std::int64_t> all(static_cast<std::size_t>(grid.total()));
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::int64_t>(i);
  std::vector<ChunkPart> parts(all.size());
  mesh_chunks(lattice, grid, options, all, parts);
  return parts;
}

}  // namespace detail::mesh

Mesh mesh_volume(const ScalarVolume& volume, const MeshOptions& options) {
  return detail::mesh::mesh_lattice(volume, options, nullptr);
}

}  // namespace voxfield
