// voxfield — one mesh file written by every rank, each its own share of the mesh (mpi.h:
// write_mesh_volume): byte for byte the file one process writes, with nothing gathered anywhere.
//
// Without an analytic value or gradient, every mesher: a rank's slab (mesh_slab.h) owns one run of
// the mesh's vertex numbers and one of its triangles, and computes the neighbour's vertices its
// triangles use itself (marching cubes, the next rank's first rows; surface nets and dual
// contouring, the rank before's last cell plane); an exclusive scan numbers them. Otherwise: the
// joined mesh numbers owned vertices chunk by chunk and orphans after them (weld.cpp), so a rank's
// chunk layers own one run of vertex numbers and claim another run of orphans, and its triangles
// are one run of the triangles; each rank learns its runs' first numbers by exclusive scans and
// the numbers of what it uses across the cuts from its neighbours (PieceWeld). Either way each rank
// then encodes its runs of every section of the file (mesh_files.h) and writes them where the scans
// of the sections' byte counts put them. The head depends only on totals every rank has (counts,
// colours, the positions' bounds), and rank 0 stages it.
#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>

#include "collective.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/mesh_files.h"
#include "voxfield/mesh_pieces.h"
#include "voxfield/mesh_slab.h"
#include "voxfield/mpi.h"

namespace voxfield::mpi {
namespace {

constexpr int kWeldTag = 7402;
using detail::kMessageBytes;

// Sends `out` to `to` and receives from `from` (either MPI_PROC_NULL): a count, then the items in
// messages of at most kMessageBytes.
template <class T>
std::vector<T> shift(MPI_Comm comm, int to, int from, const std::vector<T>& out,
                     ExchangeStats* stats) {
  detail::CollectiveTimer t(stats);
  std::uint64_t count_out = out.size(), count_in = 0;
  MPI_Sendrecv(&count_out, 1, MPI_UINT64_T, to, kWeldTag, &count_in, 1, MPI_UINT64_T, from,
               kWeldTag, comm, MPI_STATUS_IGNORE);
  // Room for what arrives, agreed on by every rank before any item moves: a rank that cannot
  // make it fails the job instead of leaving its neighbours waiting.
  std::vector<T> in;
  detail::collectively(comm, stats, [&] {
    if (from == MPI_PROC_NULL) return;
    require_memory(mul_sat(count_in, sizeof(T)), 0, "mpi::write_mesh_volume",
                   "the vertex keys a neighbour lends across a cut");
    in.resize(static_cast<std::size_t>(count_in));
  });
  const auto* send = reinterpret_cast<const std::uint8_t*>(out.data());
  auto* receive = reinterpret_cast<std::uint8_t*>(in.data());
  const std::size_t send_bytes = to == MPI_PROC_NULL ? 0 : out.size() * sizeof(T);
  const std::size_t receive_bytes = in.size() * sizeof(T);
  for (std::size_t at = 0; at < std::max(send_bytes, receive_bytes); at += kMessageBytes) {
    const int s = static_cast<int>(std::min(kMessageBytes, send_bytes - std::min(at, send_bytes)));
    const int r =
        static_cast<int>(std::min(kMessageBytes, receive_bytes - std::min(at, receive_bytes)));
    MPI_Sendrecv(send + std::min(at, send_bytes), s, MPI_BYTE, s > 0 ? to : MPI_PROC_NULL, kWeldTag,
                 receive + std::min(at, receive_bytes), r, MPI_BYTE, r > 0 ? from : MPI_PROC_NULL,
                 kWeldTag, comm, MPI_STATUS_IGNORE);
  }
  if (stats) {
    stats->bytes_sent += send_bytes + (to == MPI_PROC_NULL ? 0 : 8);
    stats->bytes_received += receive_bytes + (from == MPI_PROC_NULL ? 0 : 8);
  }
  return in;
}

// The nearest rank before (step -1) or after (+1) `rank` that holds layers; MPI_PROC_NULL if none.
int neighbour(const MeshLayers& layers, int rank, int step) {
  for (int r = rank + step; r >= 0 && r < layers.ranks(); r += step)
    if (!layers.empty(r)) return r;
  return MPI_PROC_NULL;
}

// This rank's share of the joined mesh: its part (owned vertices, claimed orphans, then its
// neighbours'), each part vertex's number, and its runs' first numbers.
struct Share {
  Mesh part;
  std::vector<std::uint32_t> global;
  std::uint64_t owned = 0, orphans = 0;
  std::uint64_t first_vertex = 0, first_orphan = 0, first_triangle = 0;
  MeshTotals totals;
  // Per part vertex: 1 when another rank's triangles may use it too (lent, numbered for the rank
  // after, or a neighbour's).
  std::vector<std::uint8_t> seam;
};

void share_totals(MPI_Comm comm, Share& s, std::uint64_t vertices, ExchangeStats* stats);

Share weld_share(MPI_Comm comm, const MeshLayers& layers, std::optional<PieceWeld> weld,
                 ExchangeStats* stats) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  // A rank without layers has no neighbours: those beside it pair with each other.
  const bool holds = !layers.empty(rank);
  const int before = holds ? neighbour(layers, rank, -1) : MPI_PROC_NULL;
  const int after = holds ? neighbour(layers, rank, +1) : MPI_PROC_NULL;
  const auto compute = [&](auto&& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    detail::collectively(comm, stats, fn);
    if (stats) stats->compute_ms += detail::ms_since(t0);
  };
  Share s;
  s.owned = weld ? weld->owned_vertices() : 0;
  const auto [first_vertex, all_owned] = detail::exclusive_scan(comm, s.owned, stats);
  s.first_vertex = first_vertex;
  // Vertices the cuts share: each rank lends its end layers' to both neighbours.
  std::vector<WeldKey> lent;
  compute([&] {
    if (weld) lent = weld->lend(s.first_vertex);
  });
  const std::vector<WeldKey> from_before = shift(comm, after, before, lent, stats);
  const std::vector<WeldKey> from_after = shift(comm, before, after, lent, stats);
  std::vector<std::uint64_t> orphan_keys;
  compute([&] {
    if (!weld) return;
    weld->borrow(from_before);
    weld->borrow(from_after);
    orphan_keys = weld->orphan_keys();
  });
  // Orphans: the rank before takes those it shares.
  const std::vector<std::uint64_t> taken = shift(comm, after, before, orphan_keys, stats);
  compute([&] {
    if (weld) weld->claim_orphans(taken);
  });
  s.orphans = weld ? weld->claimed_orphans() : 0;
  const auto [first_orphan, all_orphans] = detail::exclusive_scan(comm, s.orphans, stats);
  s.first_orphan = all_owned + first_orphan;
  std::vector<WeldKey> numbered;
  compute([&] {
    if (weld) numbered = weld->number_orphans(s.first_orphan);
  });
  const std::vector<WeldKey> orphans_before = shift(comm, after, before, numbered, stats);
  compute([&] {
    if (!weld) return;
    weld->borrow(orphans_before);
    s.part = weld->part();
    s.global = weld->global();
    weld.reset();
    s.seam.assign(s.part.vertex_count(), 0);
    std::fill(s.seam.begin() + static_cast<std::ptrdiff_t>(s.owned + s.orphans), s.seam.end(), 1);
    if (before != MPI_PROC_NULL || after != MPI_PROC_NULL)
      for (const WeldKey& k : lent) s.seam[k.number - s.first_vertex] = 1;
    if (after != MPI_PROC_NULL)
      for (const WeldKey& k : numbered) s.seam[s.owned + (k.number - s.first_orphan)] = 1;
  });
  share_totals(comm, s, all_owned + all_orphans, stats);
  return s;
}

// The share's first triangle and the totals: `vertices`, the triangles, colours, and the
// positions' bounds over every rank's written vertices.
void share_totals(MPI_Comm comm, Share& s, std::uint64_t vertices, ExchangeStats* stats) {
  std::array<float, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<float>::infinity());
  hi.fill(-std::numeric_limits<float>::infinity());
  for (std::uint64_t i = 0; i < s.owned + s.orphans; ++i)
    for (std::size_t a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], s.part.positions[i][a]);
      hi[a] = std::max(hi[a], s.part.positions[i][a]);
    }
  const auto [first_triangle, triangles] =
      detail::exclusive_scan(comm, s.part.triangle_count(), stats);
  s.first_triangle = first_triangle;
  s.totals.vertices = vertices;
  s.totals.triangles = triangles;
  {
    detail::CollectiveTimer t(stats);
    int colored = !s.part.colors.empty(), any = 0;
    MPI_Allreduce(&colored, &any, 1, MPI_INT, MPI_LOR, comm);
    s.totals.colored = any != 0;
    MPI_Allreduce(lo.data(), s.totals.lo.data(), 3, MPI_FLOAT, MPI_MIN, comm);
    MPI_Allreduce(hi.data(), s.totals.hi.data(), 3, MPI_FLOAT, MPI_MAX, comm);
  }
  if (s.totals.vertices == 0) s.totals.lo = s.totals.hi = {0, 0, 0};
}

// By slabs (mesh_slab.h): the slab's own vertices are its run of the mesh's numbers, from an
// exclusive scan; its triangles also use a neighbour's vertices, which it computed itself (the
// next rank's first rows, or the rank before's last cell plane). The vertices other ranks'
// triangles may use (the seam): those lent, and of its own those a neighbour holding layers uses
// (its first plane's rows to the rank before, its last cell plane's to the next).
Share slab_share(MPI_Comm comm, const MeshLayers& layers, std::optional<MeshSlab> slab,
                 ExchangeStats* stats) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  Share s;
  s.owned = slab ? slab->owned_vertices : 0;
  const std::pair<std::uint64_t, std::uint64_t> scanned =
      detail::exclusive_scan(comm, s.owned, stats);
  const std::uint64_t first_vertex = scanned.first, vertices = scanned.second;
  s.first_vertex = first_vertex;
  s.first_orphan = vertices;  // (no orphans: every vertex is a row's)
  detail::collectively(comm, stats, [&] {
    // One process's bound (count_rows): the same meshes refused.
    if (vertices > std::numeric_limits<std::uint32_t>::max() - 1)
      throw InvalidArgument("mesh: " + std::to_string(vertices) +
                            " vertices do not fit 32-bit indices; mesh a smaller volume");
    if (!slab) return;
    const std::uint64_t first_plane = slab->first_plane_vertices,
                        last_plane = slab->last_plane_vertices;
    s.global.resize(slab->part.vertex_count());
    for (std::size_t i = 0; i < s.global.size(); ++i)
      s.global[i] = static_cast<std::uint32_t>(slab->number(i, first_vertex));
    s.part = std::move(slab->part);
    slab.reset();
    s.seam.assign(s.part.vertex_count(), 0);
    std::fill(s.seam.begin() + static_cast<std::ptrdiff_t>(s.owned), s.seam.end(), 1);
    if (neighbour(layers, rank, -1) != MPI_PROC_NULL)
      std::fill_n(s.seam.begin(), static_cast<std::ptrdiff_t>(first_plane), 1);
    if (neighbour(layers, rank, +1) != MPI_PROC_NULL)
      std::fill(s.seam.begin() + static_cast<std::ptrdiff_t>(s.owned - last_plane),
                s.seam.begin() + static_cast<std::ptrdiff_t>(s.owned), 1);
  });
  share_totals(comm, s, vertices, stats);
  return s;
}

// Where each rank's runs go: per section, the owned vertices' run of every rank in rank order,
// then the orphans' (vertex sections), or the triangles' run of every rank (the triangle section).
std::vector<detail::FilePiece> place_runs(MPI_Comm comm, MeshFormat format, const Share& s,
                                          std::uint64_t head_bytes, ExchangeStats* stats) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const std::vector<MeshSection> sections = mesh_file_sections(format, s.totals);
  // This rank's runs: two per section (the triangle section's second is empty).
  std::vector<detail::FilePiece> runs(2 * sections.size());
  std::vector<std::uint64_t> sizes(runs.size());
  detail::collectively(comm, stats, [&] {
    for (std::size_t k = 0; k < sections.size(); ++k) {
      if (sections[k] == MeshSection::kTriangles) {
        encode_mesh_section(format, sections[k], s.part, 0, 0, s.global, runs[2 * k].bytes);
      } else {
        encode_mesh_section(format, sections[k], s.part, 0, s.owned, {}, runs[2 * k].bytes);
        encode_mesh_section(format, sections[k], s.part, s.owned, s.owned + s.orphans, {},
                            runs[2 * k + 1].bytes);
      }
      sizes[2 * k] = runs[2 * k].bytes.size();
      sizes[2 * k + 1] = runs[2 * k + 1].bytes.size();
    }
  });
  std::vector<std::uint64_t> all(sizes.size() * static_cast<std::size_t>(size));
  {
    detail::CollectiveTimer t(stats);
    MPI_Allgather(sizes.data(), static_cast<int>(sizes.size()), MPI_UINT64_T, all.data(),
                  static_cast<int>(sizes.size()), MPI_UINT64_T, comm);
  }
  if (stats) {
    stats->bytes_sent += sizes.size() * 8;
    stats->bytes_received += all.size() * 8;
  }
  // Offsets in file order: sections; within one, first runs by rank, then second runs by rank.
  std::uint64_t at = head_bytes;
  for (std::size_t slot = 0; slot < runs.size(); ++slot) {
    if (slot % 2 == 0) {
      // A section starts: its first runs, then its second runs.
      for (int pass = 0; pass < 2; ++pass)
        for (int r = 0; r < size; ++r) {
          const std::size_t i = static_cast<std::size_t>(r) * sizes.size() + slot + pass;
          if (r == rank) runs[slot + pass].offset = at;
          at += all[i];
        }
    }
  }
  return runs;
}

// The edge census over the ranks (mesh_stats): an edge two ranks' triangles share has both its
// vertices on the cuts, so the uses of edges whose vertices a neighbour may also use go to the rank
// that writes their lower vertex, which counts them; every other edge is counted where it is.
MeshStats census_over_ranks(MPI_Comm comm, const Share& s, ExchangeStats* stats);

// The file of the ranks' slabs (or, unless `slabs`, their chunked pieces: every rank passes the
// same), each rank writing its share: write_mesh_volume after its meshing.
MeshFileSummary write_parts(MPI_Comm comm, const MeshLayers& layers, MeshFormat format, bool slabs,
                            std::optional<MeshSlab> slab, std::optional<PieceWeld> weld,
                            const std::filesystem::path& path, bool census, ExchangeStats* stats,
                            FileTransaction* into);

}  // namespace

MeshFileSummary write_mesh_volume(MPI_Comm comm, const MeshLayers& layers,
                                  const ScalarVolume& frame, const float* planes,
                                  const MeshOptions& options, const std::filesystem::path& path,
                                  bool census, ExchangeStats* stats, FileTransaction* into) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const MeshFormat format = collectively(
      comm, [&] { return mesh_format_of(path); }, stats);
  int size = 1;
  MPI_Comm_size(comm, &size);
  // This rank's chunks, meshed straight into its weld.
  const auto t0 = std::chrono::steady_clock::now();
  // Slabs of the whole-volume passes; chunked pieces for an analytic value or gradient.
  const bool slabs = mesh_slab_applies(options);
  std::optional<MeshSlab> slab;
  std::optional<PieceWeld> weld;
  detail::collectively(comm, stats, [&] {
    detail::check_mesh_layers(layers, frame, options, size, "mpi::write_mesh_volume");
    if (layers.empty(rank)) return;
    const auto [z0, z1] = layers.planes(rank);
    if (slabs) {
      const auto [s0, s1] = layers.slab(rank);
      slab = mesh_slab(frame, z0, z1 - z0, planes, options, s0, s1);
    } else {
      weld.emplace(frame, z0, z1 - z0, planes, options,
                   layers.layers[static_cast<std::size_t>(rank)],
                   layers.layers[static_cast<std::size_t>(rank) + 1]);
    }
  });
  if (stats) stats->compute_ms += detail::ms_since(t0);
  return write_parts(comm, layers, format, slabs, std::move(slab), std::move(weld), path, census,
                     stats, into);
}

MeshFileSummary write_world_mesh(MPI_Comm comm, const MeshLayers& layers, const Box3i& lattice,
                                 const World& world, const MeshOptions& options, Metric metric,
                                 const std::filesystem::path& path, bool census,
                                 ExchangeStats* stats, FileTransaction* into) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const MeshFormat format = collectively(
      comm, [&] { return mesh_format_of(path); }, stats);
  const auto t0 = std::chrono::steady_clock::now();
  std::optional<MeshSlab> slab;
  detail::collectively(comm, stats, [&] {
    ScalarVolume frame;
    frame.size = lattice.size();
    // A world's slab is the same whatever its cuts (mesh_world_slab): layers of any edge, 1
    // included, whatever options.chunk_edge.
    MeshOptions cut = options;
    cut.chunk_edge = layers.chunk_edge;
    detail::check_mesh_layers(layers, frame, cut, size, "mpi::write_world_mesh");
    if (layers.empty(rank)) return;
    const auto [s0, s1] = layers.slab(rank);
    slab = mesh_world_slab(world, lattice, options, metric, s0, s1);
  });
  if (stats) stats->compute_ms += detail::ms_since(t0);
  return write_parts(comm, layers, format, /*slabs=*/true, std::move(slab), std::nullopt, path,
                     census, stats, into);
}

namespace {

MeshFileSummary write_parts(MPI_Comm comm, const MeshLayers& layers, MeshFormat format, bool slabs,
                            std::optional<MeshSlab> slab, std::optional<PieceWeld> weld,
                            const std::filesystem::path& path, bool census, ExchangeStats* stats,
                            FileTransaction* into) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const detail::OwnComm own(comm);
  Share share = slabs ? slab_share(own.comm, layers, std::move(slab), stats)
                      : weld_share(own.comm, layers, std::move(weld), stats);
  MeshFileSummary summary;
  summary.vertices = share.totals.vertices;
  summary.triangles = share.totals.triangles;
  // The census first, so that its arrays and the encoded runs are never held together.
  if (census) {
    const auto t0 = std::chrono::steady_clock::now();
    summary.census = census_over_ranks(own.comm, share, stats);
    summary.census_ms = detail::ms_since(t0);
  }
  const std::vector<std::uint8_t> head =
      detail::collectively(comm, stats, [&] { return encode_mesh_head(format, share.totals); });
  std::vector<detail::FilePiece> runs = place_runs(comm, format, share, head.size(), stats);
  share = Share{};  // the runs hold everything the file needs
  // Rank 0 stages the file with its head; every rank writes its runs; rank 0 renames it.
  std::optional<FileTransaction> own_transaction;
  FileTransaction* transaction = into;
  std::string temporary = detail::collectively(comm, stats, [&] {
    if (rank != 0) return std::string{};
    if (!transaction) transaction = &own_transaction.emplace();
    return transaction->stage_shared(path, head).string();
  });
  temporary = detail::broadcast_string(comm, temporary, stats);
  std::erase_if(runs, [](const detail::FilePiece& p) { return p.bytes.empty(); });
  const std::string error = detail::write_pieces(comm, temporary, path.string(), runs);
  detail::agree(comm, error, stats);
  detail::collectively(comm, stats, [&] {
    if (rank == 0 && own_transaction) own_transaction->commit();
  });
  return summary;
}

}  // namespace

namespace {

// One use of an edge by a triangle: its vertices' numbers (lower << 32 | upper), and whether the
// triangle runs from the lower to the upper.
struct EdgeUse {
  std::uint64_t edge = 0;
  std::uint64_t forward = 0;
  bool operator<(const EdgeUse& o) const { return edge < o.edge; }
};

// Counts sorted uses into `s` as mesh_stats does.
void count_edges(std::vector<EdgeUse>& uses, MeshStats& s) {
  std::sort(uses.begin(), uses.end());
  for (std::size_t i = 0; i < uses.size();) {
    std::size_t j = i;
    std::uint64_t forward = 0;
    while (j < uses.size() && uses[j].edge == uses[i].edge) forward += uses[j++].forward;
    s.count_edge(j - i, forward);
    i = j;
  }
}

MeshStats census_over_ranks(MPI_Comm comm, const Share& s, ExchangeStats* stats) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // Every rank's runs of numbers, to find the rank writing a vertex.
  const std::array<std::uint64_t, 4> mine{s.first_vertex, s.owned, s.first_orphan, s.orphans};
  std::vector<std::uint64_t> runs(4 * static_cast<std::size_t>(size));
  {
    detail::CollectiveTimer t(stats);
    MPI_Allgather(mine.data(), 4, MPI_UINT64_T, runs.data(), 4, MPI_UINT64_T, comm);
  }
  const auto writer = [&](std::uint64_t number) {
    for (int r = 0; r < size; ++r) {
      const std::uint64_t* q = runs.data() + 4 * static_cast<std::size_t>(r);
      if ((number >= q[0] && number - q[0] < q[1]) || (number >= q[2] && number - q[2] < q[3]))
        return r;
    }
    return 0;  // (every number is some rank's: PieceWeld numbered them)
  };
  // The part's own census counts every edge of its triangles; those of the seam are taken out
  // and counted again by their writers, with every rank's uses of them.
  MeshStats local;
  std::vector<std::vector<EdgeUse>> away(static_cast<std::size_t>(size));
  detail::collectively(comm, stats, [&] {
    local = mesh_stats(s.part);
    for (std::size_t t = 0; t < s.part.triangle_count(); ++t)
      for (std::size_t k = 0; k < 3; ++k) {
        const std::uint32_t a = s.part.indices[3 * t + k], b = s.part.indices[3 * t + (k + 1) % 3];
        if (!s.seam[a] || !s.seam[b]) continue;
        const std::uint64_t ga = s.global[a], gb = s.global[b];
        away[static_cast<std::size_t>(writer(std::min(ga, gb)))].push_back(
            {std::min(ga, gb) << 32 | std::max(ga, gb), ga < gb ? 1u : 0u});
      }
  });
  // The seam's uses to their writers, in one all-to-all.
  std::vector<int> send_counts(static_cast<std::size_t>(size)), receive_counts(send_counts.size());
  std::vector<int> send_at(send_counts.size()), receive_at(send_counts.size());
  std::vector<EdgeUse> outgoing;
  detail::collectively(comm, stats, [&] {
    for (int r = 0; r < size; ++r) {
      const auto& list = away[static_cast<std::size_t>(r)];
      if (outgoing.size() + list.size() > std::numeric_limits<int>::max() / sizeof(EdgeUse))
        throw ResourceLimitError("mpi::write_mesh_volume: the census's seam edges pass 2 GiB");
      send_at[static_cast<std::size_t>(r)] = static_cast<int>(outgoing.size() * sizeof(EdgeUse));
      send_counts[static_cast<std::size_t>(r)] = static_cast<int>(list.size() * sizeof(EdgeUse));
      outgoing.insert(outgoing.end(), list.begin(), list.end());
    }
  });
  std::vector<EdgeUse> incoming;
  {
    detail::CollectiveTimer t(stats);
    MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, comm);
  }
  // Room for the uses that arrive, agreed on before any moves (MPI counts bytes in an int).
  detail::collectively(comm, stats, [&] {
    std::size_t bytes = 0;
    for (std::size_t r = 0; r < receive_counts.size(); ++r) {
      if (bytes > static_cast<std::size_t>(std::numeric_limits<int>::max()) -
                      static_cast<std::size_t>(receive_counts[r]))
        throw ResourceLimitError("mpi::write_mesh_volume: the census's seam edges pass 2 GiB");
      receive_at[r] = static_cast<int>(bytes);
      bytes += static_cast<std::size_t>(receive_counts[r]);
    }
    require_memory(bytes, 0, "mpi::write_mesh_volume", "the seam edges' uses");
    incoming.resize(bytes / sizeof(EdgeUse));
  });
  {
    detail::CollectiveTimer t(stats);
    MPI_Alltoallv(outgoing.data(), send_counts.data(), send_at.data(), MPI_BYTE, incoming.data(),
                  receive_counts.data(), receive_at.data(), MPI_BYTE, comm);
    if (stats) {  // what travels: a rank's uses of the edges it writes stay with it
      const auto self = static_cast<std::size_t>(rank);
      stats->bytes_sent += outgoing.size() * sizeof(EdgeUse) - send_counts[self];
      stats->bytes_received += incoming.size() * sizeof(EdgeUse) - receive_counts[self];
    }
  }
  MeshStats seam_here, seam_all;
  detail::collectively(comm, stats, [&] {
    count_edges(outgoing, seam_here);
    count_edges(incoming, seam_all);
  });
  std::array<std::uint64_t, 5> counts{
      local.edges - seam_here.edges + seam_all.edges,
      local.boundary_edges - seam_here.boundary_edges + seam_all.boundary_edges,
      local.nonmanifold_edges - seam_here.nonmanifold_edges + seam_all.nonmanifold_edges,
      local.misoriented_edges - seam_here.misoriented_edges + seam_all.misoriented_edges,
      local.degenerate_triangles};
  std::array<double, 2> measures{local.area_units2, local.signed_volume_units3};
  {
    detail::CollectiveTimer t(stats);
    MPI_Allreduce(MPI_IN_PLACE, counts.data(), 5, MPI_UINT64_T, MPI_SUM, comm);
    MPI_Allreduce(MPI_IN_PLACE, measures.data(), 2, MPI_DOUBLE, MPI_SUM, comm);
  }
  MeshStats all;
  all.vertices = s.totals.vertices;
  all.triangles = s.totals.triangles;
  all.edges = counts[0];
  all.boundary_edges = counts[1];
  all.nonmanifold_edges = counts[2];
  all.misoriented_edges = counts[3];
  all.degenerate_triangles = counts[4];
  all.euler_characteristic = static_cast<std::int64_t>(all.vertices) -
                             static_cast<std::int64_t>(all.edges) +
                             static_cast<std::int64_t>(all.triangles);
  all.area_units2 = measures[0];
  all.signed_volume_units3 = measures[1];
  return all;
}

}  // namespace

}  // namespace voxfield::mpi
