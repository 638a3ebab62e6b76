// voxfield — meshes of a lattice split over the ranks of an MPI job (mpi.h).
//
// The chunked mesher's chunks grouped into layers along z (mesh_pieces.h) are dealt to the ranks
// in runs, of equal length or of equal weight (the surface each layer holds); a run reads its
// cells' sample planes, three below and two above, so a rank needs nothing from the others while
// meshing.
//
// Every mesher without an analytic value or gradient: each rank meshes its run's sample planes as
// a slab in the whole-volume passes (mesh_slab.h), which number vertices and triangles by lattice
// row — its vertices and triangles are one run of the mesh one process makes, so an exclusive scan
// of the vertex counts numbers them and rank 0 only lays the runs end to end.
//
// With an analytic value or gradient: each rank's piece — its chunks' parts with their vertices'
// lattice element keys — goes to rank 0, which joins them with the chunked mesher's weld: border
// vertices are computed the same way on both sides of a cut and welded by key, so the cut leaves
// no crack and no duplicate, and the mesh is the same array for array for any number of ranks.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <string>

#include "collective.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_pieces.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/mpi.h"

namespace voxfield::mpi {

bool MeshLayers::empty(int rank) const {
  return layers[static_cast<std::size_t>(rank)] == layers[static_cast<std::size_t>(rank) + 1];
}

std::pair<int, int> MeshLayers::slab(int rank) const {
  if (empty(rank)) return {0, 0};
  const int last_plane = samples.z - 1;
  const int begin = layers[static_cast<std::size_t>(rank)] * chunk_edge;
  const int end = std::min(layers[static_cast<std::size_t>(rank) + 1] * chunk_edge, last_plane);
  return {begin, end == last_plane ? samples.z : end};
}

std::pair<int, int> MeshLayers::planes(int rank) const {
  if (empty(rank)) return {0, 0};
  return mesh_layer_planes(samples, chunk_edge, layers[static_cast<std::size_t>(rank)],
                           layers[static_cast<std::size_t>(rank) + 1]);
}

MeshLayers partition_mesh_layers(Vec3i samples, int chunk_edge, int ranks) {
  if (ranks < 1) throw InvalidArgument("partition_mesh_layers: ranks must be at least 1");
  const int count = mesh_chunk_layers(samples, chunk_edge);
  MeshLayers p;
  p.samples = samples;
  p.chunk_edge = chunk_edge;
  p.layers.resize(static_cast<std::size_t>(ranks) + 1);
  for (int r = 0; r <= ranks; ++r)
    p.layers[static_cast<std::size_t>(r)] =
        static_cast<std::int32_t>(static_cast<std::int64_t>(count) * r / ranks);
  return p;
}

MeshLayers partition_mesh_layers(Vec3i samples, int chunk_edge, int ranks,
                                 const std::vector<double>& layer_weights) {
  MeshLayers p = partition_mesh_layers(samples, chunk_edge, ranks);
  const std::size_t count = static_cast<std::size_t>(p.layers.back());
  if (layer_weights.size() != count)
    throw InvalidArgument("partition_mesh_layers: " + std::to_string(layer_weights.size()) +
                          " weights for " + std::to_string(count) + " chunk layers");
  // prefix[k]: the weight of the layers before k.
  std::vector<double> prefix(count + 1, 0.0);
  for (std::size_t k = 0; k < count; ++k) {
    if (!(layer_weights[k] >= 0) || !std::isfinite(layer_weights[k]))
      throw InvalidArgument("partition_mesh_layers: layer " + std::to_string(k) + "'s weight " +
                            std::to_string(layer_weights[k]) + " is not a finite weight >= 0");
    prefix[k + 1] = prefix[k] + layer_weights[k];
  }
  // Each cut where the running weight comes nearest to its share (never before the previous cut).
  std::size_t k = 0;
  for (int r = 1; r < ranks; ++r) {
    const double target = prefix[count] * r / ranks;
    while (k < count && prefix[k + 1] <= target) ++k;
    if (k < count && target - prefix[k] > prefix[k + 1] - target) ++k;
    p.layers[static_cast<std::size_t>(r)] = static_cast<std::int32_t>(k);
  }
  return p;
}

std::vector<double> mesh_layer_weights(MPI_Comm comm, Vec3i samples, int z0, int z1,
                                       const float* planes, const MeshOptions& options,
                                       ExchangeStats* stats) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t nz = static_cast<std::size_t>(std::max(samples.z, 0));
  // Per plane: the crossed edges counted by the rank holding it, and how many ranks hold it.
  std::vector<std::uint64_t> own(2 * nz, 0);
  detail::collectively(comm, stats, [&] {
    mesh_chunk_layers(samples, options.chunk_edge);  // refuses a bad lattice or chunk edge
    if (!(z0 >= 0 && z0 <= z1 && z1 <= samples.z) || (z1 > z0 && !planes))
      throw InvalidArgument("mesh_layer_weights: planes [" + std::to_string(z0) + ", " +
                            std::to_string(z1) + ") are not within the lattice's " +
                            std::to_string(samples.z));
    const float iso = static_cast<float>(options.iso);
    const bool above = options.inside_above;
    const std::size_t nx = static_cast<std::size_t>(samples.x),
                      ny = static_cast<std::size_t>(samples.y);
    std::vector<std::uint8_t> in(nx * ny);
    for (int z = z0; z < z1; ++z) {
      const float* p = planes + nx * ny * static_cast<std::size_t>(z - z0);
      for (std::size_t i = 0; i < in.size(); ++i) in[i] = above ? p[i] > iso : p[i] < iso;
      std::uint64_t crossed = 0;
      for (std::size_t y = 0; y < ny; ++y)
        for (std::size_t x = 0; x < nx; ++x) {
          const std::size_t i = x + nx * y;
          crossed += (x + 1 < nx && in[i] != in[i + 1]) + (y + 1 < ny && in[i] != in[i + nx]);
        }
      own[static_cast<std::size_t>(z)] = crossed;
      own[nz + static_cast<std::size_t>(z)] = 1;
    }
  });
  if (stats) stats->compute_ms += detail::ms_since(t0);
  std::vector<std::uint64_t> all(own.size());
  {
    detail::CollectiveTimer t(stats);
    MPI_Allreduce(own.data(), all.data(), static_cast<int>(all.size()), MPI_UINT64_T, MPI_SUM,
                  comm);
  }
  if (stats) {
    stats->bytes_sent += own.size() * sizeof(std::uint64_t);
    stats->bytes_received += all.size() * sizeof(std::uint64_t);
  }
  return detail::collectively(comm, stats, [&] {
    for (std::size_t z = 0; z < nz; ++z)
      if (all[nz + z] != 1)
        throw InvalidArgument("mesh_layer_weights: sample plane " + std::to_string(z) +
                              " was passed by " + std::to_string(all[nz + z]) +
                              " ranks; each plane by exactly one");
    const int edge = options.chunk_edge;
    const int layers = mesh_chunk_layers(samples, edge);
    const double per_plane = static_cast<double>(samples.x) * samples.y / 64.0;
    std::vector<double> weights(static_cast<std::size_t>(layers), 0.0);
    for (int k = 0; k < layers; ++k)
      // The planes of layer k's cells: k * edge .. (k + 1) * edge, within the lattice.
      for (int z = k * edge; z <= std::min((k + 1) * edge, samples.z - 1); ++z)
        weights[static_cast<std::size_t>(k)] +=
            static_cast<double>(all[static_cast<std::size_t>(z)]) + per_plane;
    return weights;
  });
}

namespace {

constexpr int kPieceTag = 7401;
using detail::kMessageBytes;

// Every rank's piece on rank 0 (in rank order; empty on the others). Sizes first, then each
// piece in messages of at most kMessageBytes.
std::vector<std::vector<std::uint8_t>> gather_pieces(MPI_Comm comm, std::vector<std::uint8_t> own,
                                                     ExchangeStats* stats) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::vector<std::uint64_t> sizes(static_cast<std::size_t>(size));
  const std::uint64_t own_size = own.size();
  {
    detail::CollectiveTimer t(stats);
    MPI_Gather(&own_size, 1, MPI_UINT64_T, sizes.data(), 1, MPI_UINT64_T, 0, comm);
  }
  std::vector<std::vector<std::uint8_t>> pieces;
  // Rank 0 makes room for every piece before any is sent: past the memory limit, or where the
  // allocation fails, every rank learns it here instead of waiting on a rank 0 that has left.
  detail::collectively(comm, stats, [&] {
    if (rank != 0) return;
    std::uint64_t total = 0;
    for (const std::uint64_t n : sizes) total = add_sat(total, n);
    require_memory(total, 0, "mpi::mesh_volume", "the pieces of the mesh on rank 0");
    pieces.resize(static_cast<std::size_t>(size));
    for (int r = 1; r < size; ++r)
      pieces[static_cast<std::size_t>(r)].resize(
          static_cast<std::size_t>(sizes[static_cast<std::size_t>(r)]));
  });
  detail::CollectiveTimer t(stats);
  if (rank != 0) {
    for (std::size_t at = 0; at < own.size(); at += kMessageBytes) {
      const int n = static_cast<int>(std::min(kMessageBytes, own.size() - at));
      MPI_Send(own.data() + at, n, MPI_BYTE, 0, kPieceTag, comm);
    }
    if (stats) stats->bytes_sent += own_size;
    return pieces;
  }
  pieces[0] = std::move(own);
  for (int r = 1; r < size; ++r) {
    std::vector<std::uint8_t>& piece = pieces[static_cast<std::size_t>(r)];
    for (std::size_t at = 0; at < piece.size(); at += kMessageBytes) {
      const int n = static_cast<int>(std::min(kMessageBytes, piece.size() - at));
      MPI_Recv(piece.data() + at, n, MPI_BYTE, r, kPieceTag, comm, MPI_STATUS_IGNORE);
    }
    if (stats) stats->bytes_received += piece.size();
  }
  return pieces;
}

// A rank's run of the mesh, for rank 0: its vertex and index counts, its vertices' positions and
// normals, its triangles' indices numbered in the whole mesh.
std::vector<std::uint8_t> run_bytes(const MeshSlab& slab, std::uint64_t first_vertex) {
  const std::uint64_t counts[2] = {slab.owned_vertices, slab.part.indices.size()};
  const std::size_t vertex_bytes = static_cast<std::size_t>(slab.owned_vertices) * 12;
  std::vector<std::uint8_t> bytes(sizeof counts + 2 * vertex_bytes + 4 * counts[1]);
  std::uint8_t* at = bytes.data();
  const auto put = [&](const void* from, std::size_t n) {
    if (n > 0) std::memcpy(at, from, n);
    at += n;
  };
  put(counts, sizeof counts);
  put(slab.part.positions.data(), vertex_bytes);
  put(slab.part.normals.data(), vertex_bytes);
  for (const std::uint32_t i : slab.part.indices) {
    const auto number = static_cast<std::uint32_t>(slab.number(i, first_vertex));
    put(&number, 4);
  }
  return bytes;
}

// The runs laid end to end, in rank order (rank 0 made room for them: gather_pieces).
Mesh lay_runs(const std::vector<std::vector<std::uint8_t>>& runs, std::uint64_t vertices,
              std::uint64_t indices) {
  require_memory(add_sat(mul_sat(vertices, 24), mul_sat(indices, 4)), 0, "mpi::mesh_volume",
                 "the mesh on rank 0");
  Mesh mesh;
  mesh.positions.reserve(static_cast<std::size_t>(vertices));
  mesh.normals.reserve(static_cast<std::size_t>(vertices));
  mesh.indices.reserve(static_cast<std::size_t>(indices));
  for (const std::vector<std::uint8_t>& run : runs) {
    if (run.empty()) continue;
    std::uint64_t counts[2];
    std::memcpy(counts, run.data(), sizeof counts);
    const std::uint8_t* at = run.data() + sizeof counts;
    const std::size_t n = static_cast<std::size_t>(counts[0]);
    const std::size_t m = static_cast<std::size_t>(counts[1]);
    const std::size_t v0 = mesh.positions.size(), i0 = mesh.indices.size();
    mesh.positions.resize(v0 + n);
    mesh.normals.resize(v0 + n);
    mesh.indices.resize(i0 + m);
    if (n > 0) {
      std::memcpy(mesh.positions.data() + v0, at, 12 * n);
      std::memcpy(mesh.normals.data() + v0, at + 12 * n, 12 * n);
    }
    if (m > 0) std::memcpy(mesh.indices.data() + i0, at + 24 * n, 4 * m);
  }
  return mesh;
}

// mesh_volume by slabs (mesh_slab.h): each rank's slab, a scan of the vertex counts, the runs
// laid end to end on rank 0.
Mesh mesh_by_slabs(MPI_Comm comm, const MeshLayers& layers, const ScalarVolume& frame,
                   const float* planes, const MeshOptions& options, ExchangeStats* stats) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<MeshSlab> slab;
  detail::collectively(comm, stats, [&] {
    if (layers.empty(rank)) return;
    const auto [z0, z1] = layers.planes(rank);
    const auto [s0, s1] = layers.slab(rank);
    slab = mesh_slab(frame, z0, z1 - z0, planes, options, s0, s1);
  });
  if (stats) stats->compute_ms += detail::ms_since(t0);
  // (Plain variables, not a structured binding: the lambdas below capture them, which clang 14
  // refuses for bindings.)
  const std::pair<std::uint64_t, std::uint64_t> scanned =
      detail::exclusive_scan(comm, slab ? slab->owned_vertices : 0, stats);
  const std::uint64_t first_vertex = scanned.first, vertices = scanned.second;
  const std::uint64_t indices =
      detail::exclusive_scan(comm, slab ? slab->part.indices.size() : 0, stats).second;
  std::vector<std::uint8_t> run = detail::collectively(comm, stats, [&] {
    // One process's bound (count_rows): the same meshes refused.
    if (vertices > std::numeric_limits<std::uint32_t>::max() - 1)
      throw InvalidArgument("mesh: " + std::to_string(vertices) +
                            " vertices do not fit 32-bit indices; mesh a smaller volume");
    return slab ? run_bytes(*slab, first_vertex) : std::vector<std::uint8_t>{};
  });
  slab.reset();
  const detail::OwnComm own(comm);
  const std::vector<std::vector<std::uint8_t>> runs =
      gather_pieces(own.comm, std::move(run), stats);
  const auto t1 = std::chrono::steady_clock::now();
  Mesh mesh = detail::collectively(
      comm, stats, [&] { return rank == 0 ? lay_runs(runs, vertices, indices) : Mesh{}; });
  if (stats) stats->compute_ms += detail::ms_since(t1);
  return mesh;
}

}  // namespace

namespace detail {

void check_mesh_layers(const MeshLayers& layers, const ScalarVolume& frame,
                       const MeshOptions& options, int ranks, const char* who) {
  if (layers.ranks() != ranks)
    throw InvalidArgument(std::string(who) + ": the layers are dealt to " +
                          std::to_string(layers.ranks()) + " ranks, the communicator has " +
                          std::to_string(ranks));
  if (!(layers.samples == frame.size) || layers.chunk_edge != options.chunk_edge)
    throw InvalidArgument(std::string(who) +
                          ": the layers were cut for another lattice size or chunk edge");
  // The runs must cover every layer once, in order (a layer no rank meshes is a hole). Layers of
  // one cell plane (edge 1) are write_world_mesh's: any cuts.
  const int count = layers.chunk_edge == 1 ? layers.samples.z - 1
                                           : mesh_chunk_layers(layers.samples, layers.chunk_edge);
  for (std::size_t r = 0; r < layers.layers.size(); ++r)
    if ((r == 0 && layers.layers[r] != 0) ||
        (r + 1 == layers.layers.size() && layers.layers[r] != count) ||
        (r > 0 && layers.layers[r] < layers.layers[r - 1]))
      throw InvalidArgument(std::string(who) + ": the runs of layers do not cover the lattice's " +
                            std::to_string(count) + " layers once, in rank order");
}

}  // namespace detail

Mesh mesh_volume(MPI_Comm comm, const MeshLayers& layers, const ScalarVolume& frame,
                 const float* planes, const MeshOptions& options, ExchangeStats* stats) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  detail::collectively(comm, stats, [&] {
    detail::check_mesh_layers(layers, frame, options, size, "mpi::mesh_volume");
  });
  if (mesh_slab_applies(options)) return mesh_by_slabs(comm, layers, frame, planes, options, stats);
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::uint8_t> piece = detail::collectively(comm, stats, [&] {
    if (layers.empty(rank)) return std::vector<std::uint8_t>{};
    const auto [z0, z1] = layers.planes(rank);
    return mesh_piece(frame, z0, z1 - z0, planes, options,
                      layers.layers[static_cast<std::size_t>(rank)],
                      layers.layers[static_cast<std::size_t>(rank) + 1]);
  });
  if (stats) stats->compute_ms += detail::ms_since(t0);
  // The pieces travel on a communicator of their own, so that no message of the application's on
  // `comm` can match theirs.
  const detail::OwnComm own(comm);
  const std::vector<std::vector<std::uint8_t>> pieces =
      gather_pieces(own.comm, std::move(piece), stats);
  const auto t1 = std::chrono::steady_clock::now();
  Mesh mesh = detail::collectively(comm, stats, [&] {
    if (rank != 0) return Mesh{};
    std::vector<std::span<const std::uint8_t>> spans;
    for (int r = 0; r < size; ++r)
      if (!layers.empty(r)) spans.emplace_back(pieces[static_cast<std::size_t>(r)]);
    return join_mesh_pieces(spans);
  });
  if (stats) stats->compute_ms += detail::ms_since(t1);
  return mesh;
}

}  // namespace voxfield::mpi
