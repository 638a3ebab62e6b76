// voxfield-mpi mesh WORLD (mesh_command.h): a world's surface meshed over the ranks, the file
// `voxfield mesh WORLD` writes, byte for byte.
//
// mesh_world's lattice is the world's content bounds grown by two voxels of air, which no rank
// knows before the world is read: a first reading in slabs of equal volume finds them (and where
// the surface lies, to deal the chunk layers by content), then each rank reads again the slices
// its layers' rows need — their planes and the exact field's clamp beyond
// (mesh_world_slab_voxels) — and meshes them (mpi::write_world_mesh). The second reading's slabs
// must still cover the file's whole domain (load_world_slab): rank 0 also reads the air below the
// lattice and the last rank the air above it, whether they mesh anything or not.
#include <algorithm>
#include <cmath>
#include <limits>

#include "mesh_command.h"
#include "rank_stats.h"
#include "voxfield/error.h"
#include "voxfield/mesh.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_pieces.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/parallel.h"

namespace voxfield::mpi_cli {
namespace {

constexpr int kWorldChunk = 16;  // the world's chunks as read (the mesh's are --chunk)

// Per chunk layer of `lattice` (cells [k, k + 1) * edge from its first plane), the weight of the
// world's units it covers (content_unit_weights: unit u spans units[u]'s slices), shared by
// overlap.
std::vector<double> layer_weights(const Box3i& lattice, int edge, const std::vector<Box3i>& units,
                                  const std::vector<double>& unit_weights) {
  const int layers = mesh_chunk_layers(lattice.size(), edge);
  std::vector<double> w(static_cast<std::size_t>(layers), 0.0);
  for (int k = 0; k < layers; ++k) {
    const int z0 = lattice.begin.z + k * edge;
    const int z1 = std::min(z0 + edge + 1, lattice.end.z);  // the layer's sample planes
    for (std::size_t u = 0; u < units.size(); ++u) {
      const int a = std::max(z0, units[u].begin.z), b = std::min(z1, units[u].end.z);
      if (b > a)
        w[static_cast<std::size_t>(k)] +=
            unit_weights[u] * (b - a) / std::max(1, units[u].size().z);
    }
  }
  return w;
}

// The second reading's slabs of `domain`: each rank's from its layers' first cell plane (so that
// what it meshes lies within its slab but for the reach the ghost slices add), every slab
// non-empty; and the ghost slices that give every rank with layers what it reads.
std::pair<mpi::SlabPartition, int> reading_cut(const Box3i& domain, const Box3i& lattice,
                                               const mpi::MeshLayers& layers, Mesher mesher) {
  const int ranks = layers.ranks();
  mpi::SlabPartition p;
  p.domain = domain;
  p.z.assign(static_cast<std::size_t>(ranks) + 1, 0);
  p.z.front() = domain.begin.z;
  p.z.back() = domain.end.z;
  for (int r = 1; r < ranks; ++r) {
    const std::int64_t first =
        std::int64_t{lattice.begin.z} +
        std::int64_t{layers.layers[static_cast<std::size_t>(r)]} * layers.chunk_edge;
    p.z[static_cast<std::size_t>(r)] = static_cast<std::int32_t>(
        std::clamp<std::int64_t>(first, domain.begin.z + r, domain.end.z - (ranks - r)));
  }
  for (int r = 1; r < ranks; ++r)  // strictly increasing (the clamp keeps room for the rest)
    p.z[static_cast<std::size_t>(r)] =
        std::max(p.z[static_cast<std::size_t>(r)], p.z[static_cast<std::size_t>(r) - 1] + 1);
  std::int64_t ghost = 0;
  for (int r = 0; r < ranks; ++r) {
    if (layers.empty(r)) continue;
    const auto [s0, s1] = layers.slab(r);
    const auto [v0, v1] = mesh_world_slab_voxels(lattice, s0, s1, mesher);
    const Box3i slab = p.slab(r);
    // Only slices within the domain are read (beyond it is air).
    const std::int64_t below = std::int64_t{slab.begin.z} - std::max(v0, domain.begin.z);
    const std::int64_t above = std::int64_t{std::min(v1, domain.end.z)} - slab.end.z;
    ghost = std::max({ghost, below, above});
  }
  return {p, static_cast<int>(std::min<std::int64_t>(ghost, domain.size().z))};
}

}  // namespace

int run_world_mesh(MPI_Comm comm, const MeshSettings& s) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  if (s.iso != 0)
    throw InvalidArgument("--iso " + std::to_string(s.iso) + ": voxfield-mpi meshes a world's " +
                          "surface at iso 0 (an offset surface's normals and colours come from " +
                          "the nearest voxels, in any rank's slab); voxfield mesh meshes " + s.in +
                          " at any iso");
  if (s.inside != "below" || !s.spacing.empty())
    throw InvalidArgument(
        "--inside and --spacing are for float volumes; a world's solid voxels are inside, one "
        "unit per voxel");
  std::optional<ThreadLimit> limit;
  if (s.threads > 0) limit.emplace(s.threads);
  MeshOptions options;
  options.algorithm = parse_mesher(s.algorithm);
  options.chunk_edge = s.chunk;
  const Metric metric = parse_metric(s.metric.value_or("euclidean"));
  const mpi::SlabReadOptions read = slab_read_options(s.read);
  const double t0 = MPI_Wtime();
  mpi::ExchangeStats ex;
  // The first reading: the domain, the content's bounds and where the surface lies.
  Box3i domain, content;
  std::vector<double> unit_weights;
  std::vector<Box3i> units;
  {
    const mpi::WorldSlab first = mpi::load_world_slab(comm, s.in, kWorldChunk, 0, read);
    domain = first.partition.domain;
    content = mpi::content_bounds(comm, first.partition, first.world);
    if (s.balance == "content") {
      unit_weights =
          mpi::content_unit_weights(comm, first.partition, first.world, kWorldChunk, &ex);
      units = mpi::slab_units(domain, kWorldChunk);
    }
  }
  std::optional<FileTransaction> outputs;
  if (rank == 0) outputs.emplace();
  if (content.empty()) {  // no surface: the empty mesh voxfield mesh writes
    const double t1 = MPI_Wtime();
    mpi::collectively(comm, [&] {
      if (rank == 0) outputs->stage(s.out, encode_mesh(Mesh{}, mesh_format_of(s.out)));
    });
    mpi::MeshFileSummary none;
    none.census = MeshStats{};
    return finish_mesh(comm, s, none, t1, ex, outputs, {{"chunk_layers", 0}});
  }
  const Box3i lattice = content.grown(mesh_world_margin(0));
  const mpi::MeshLayers layers = mpi::collectively(comm, [&] {
    return units.empty()
               ? mpi::partition_mesh_layers(lattice.size(), s.chunk, size)
               : mpi::partition_mesh_layers(lattice.size(), s.chunk, size,
                                            layer_weights(lattice, s.chunk, units, unit_weights));
  });
  // The second reading: each rank's slices.
  // (Named values, not a structured binding: the lambda below captures the cut, and clang 14,
  // which CI's sanitizer builds use, cannot capture a binding.)
  const std::pair<mpi::SlabPartition, int> cut_and_ghost = mpi::collectively(
      comm, [&] { return reading_cut(domain, lattice, layers, options.algorithm); });
  const mpi::SlabPartition& cut = cut_and_ghost.first;
  const int ghost = cut_and_ghost.second;
  const mpi::WorldSlab mine = mpi::load_world_slab(
      comm, s.in, kWorldChunk, ghost, [&](const Box3i&) { return cut; }, read);
  const double load_ms = max_over(comm, (MPI_Wtime() - t0) * 1e3);
  MPI_Barrier(comm);  // the mesh's time starts together on every rank
  const double t1 = MPI_Wtime();
  const mpi::MeshFileSummary mesh =
      mpi::write_world_mesh(comm, layers, lattice, mine.world, options, metric, s.out,
                            !s.stats.empty(), &ex, outputs ? &*outputs : nullptr);
  return finish_mesh(comm, s, mesh, t1, ex, outputs,
                     {{"load_ms_max", load_ms},
                      {"chunk_layers", layers.layers},
                      {"balance", s.balance},
                      {"lattice",
                       {lattice.begin.x, lattice.begin.y, lattice.begin.z, lattice.end.x,
                        lattice.end.y, lattice.end.z}},
                      {"ghost_slices", ghost},
                      {"read", read_name(mine.read_by)},
                      {"read_in_parts", mine.read_in_parts}});
}

nlohmann::json write_edited_world_mesh(MPI_Comm comm, const mpi::SlabPartition& partition,
                                       const World& world, Mesher algorithm,
                                       const std::string& path, FileTransaction* into) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const double t0 = MPI_Wtime();
  mpi::ExchangeStats ex;
  const Box3i content = mpi::content_bounds(comm, partition, world);
  if (content.empty()) {  // no surface: the empty mesh voxfield mesh writes
    mpi::collectively(comm, [&] {
      if (rank == 0) into->stage(path, encode_mesh(Mesh{}, mesh_format_of(path)));
    });
    return {{"triangles", 0},
            {"vertices", 0},
            {"algorithm", mesher_name(algorithm)},
            {"ms", max_over(comm, (MPI_Wtime() - t0) * 1e3)},
            {"exchange", exchange_json(comm, ex)}};
  }
  // Each rank meshes the lattice's rows within its own slab (layers of one cell plane: cut
  // wherever the slabs are), from the slices beyond it its world keeps.
  const Box3i lattice = content.grown(mesh_world_margin(0));
  mpi::MeshLayers layers;
  layers.samples = lattice.size();
  layers.chunk_edge = 1;
  const std::int64_t cells = layers.samples.z - 1;
  for (const std::int32_t z : partition.z)
    layers.layers.push_back(static_cast<std::int32_t>(
        std::clamp<std::int64_t>(std::int64_t{z} - lattice.begin.z, 0, cells)));
  layers.layers.front() = 0;
  layers.layers.back() = static_cast<std::int32_t>(cells);
  MeshOptions options;
  options.algorithm = algorithm;
  const mpi::MeshFileSummary mesh = mpi::write_world_mesh(
      comm, layers, lattice, world, options, Metric::kEuclidean, path, false, &ex, into);
  return {{"triangles", mesh.triangles},
          {"vertices", mesh.vertices},
          {"algorithm", mesher_name(algorithm)},
          {"ms", max_over(comm, (MPI_Wtime() - t0) * 1e3)},
          {"exchange", exchange_json(comm, ex)}};
}

}  // namespace voxfield::mpi_cli
