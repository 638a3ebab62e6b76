// voxfield — frames of a world split over the ranks (mpi.h; render_relay.h): every rank walks its
// stretch of every primary ray at once, and every pixel's first hit is the MINLOC over the ranks of
// their hits. The shadow rays of those hits are relayed between the slabs, each leg sent to the
// rank whose slab holds its voxel, until no rank has one. Then every pixel's shadow is the minimum
// over the ranks of the shadows their walks ended with, and the frame the per-byte maximum of the
// ranks' shaded pixels (each pixel shaded by one rank alone, the others' bytes zero), which rank 0
// finishes with the sky.
#include <mpi.h>

#include <algorithm>
#include <cstddef>
#include <memory>
#include <type_traits>
#include <vector>

#include "collective.h"
#include "voxfield/mpi.h"
#include "voxfield/render_relay.h"

namespace voxfield::mpi {

namespace {

static_assert(std::is_trivially_copyable_v<RayLeg> && sizeof(RayLeg) == 64,
              "legs cross processes as bytes, every one of them set");
// MPI_DOUBLE_INT is the pair struct { double; int; }, elements that far apart.
struct DoubleInt {
  double value;
  int index;
};
static_assert(std::is_trivially_copyable_v<RelayHit> && std::is_standard_layout_v<RelayHit> &&
                  offsetof(RelayHit, t) == offsetof(DoubleInt, value) &&
                  offsetof(RelayHit, along) == offsetof(DoubleInt, index) &&
                  sizeof(RelayHit) == sizeof(DoubleInt) && sizeof(std::int32_t) == sizeof(int),
              "hits are reduced as MPI_DOUBLE_INT");

// The rank whose slab holds slice z.
int owner_of(const SlabPartition& partition, std::int32_t z) {
  const auto it = std::upper_bound(partition.z.begin() + 1, partition.z.end() - 1, z);
  return static_cast<int>(it - (partition.z.begin() + 1));
}

// Sends every leg to the rank of its voxel's slab; returns the legs this rank received. Every
// allocation is agreed on before the next collective call, so a rank that runs out of memory fails
// the job on every rank instead of leaving the others waiting.
std::vector<RayLeg> route(MPI_Comm comm, const SlabPartition& partition,
                          const std::vector<RayLeg>& legs, MPI_Datatype leg_type,
                          ExchangeStats* stats) {
  const auto size = static_cast<std::size_t>(partition.ranks());
  std::vector<int> send_counts(size), send_offsets(size), receive_counts(size),
      receive_offsets(size);
  const std::vector<RayLeg> out = detail::collectively(comm, stats, [&] {
    std::vector<std::vector<RayLeg>> to(size);
    for (const RayLeg& leg : legs)
      to[static_cast<std::size_t>(owner_of(partition, leg.voxel.z))].push_back(leg);
    std::vector<RayLeg> sorted;
    sorted.reserve(legs.size());
    for (std::size_t r = 0; r < size; ++r) {
      send_offsets[r] = static_cast<int>(sorted.size());
      send_counts[r] = static_cast<int>(to[r].size());
      sorted.insert(sorted.end(), to[r].begin(), to[r].end());
    }
    return sorted;
  });
  {
    detail::CollectiveTimer timer(stats);
    MPI_Alltoall(send_counts.data(), 1, MPI_INT, receive_counts.data(), 1, MPI_INT, comm);
  }
  std::vector<RayLeg> in = detail::collectively(comm, stats, [&] {
    std::size_t received = 0;
    for (std::size_t r = 0; r < size; ++r) {
      receive_offsets[r] = static_cast<int>(received);
      received += static_cast<std::size_t>(receive_counts[r]);
    }
    return std::vector<RayLeg>(received);
  });
  {
    detail::CollectiveTimer timer(stats);
    MPI_Alltoallv(out.data(), send_counts.data(), send_offsets.data(), leg_type, in.data(),
                  receive_counts.data(), receive_offsets.data(), leg_type, comm);
  }
  if (stats) {
    stats->bytes_sent += out.size() * sizeof(RayLeg);
    stats->bytes_received += in.size() * sizeof(RayLeg);
  }
  return in;
}

// A leg as MPI sees it: its bytes, one element.
class LegType {
 public:
  LegType() {
    MPI_Type_contiguous(static_cast<int>(sizeof(RayLeg)), MPI_BYTE, &type_);
    MPI_Type_commit(&type_);
  }
  ~LegType() { MPI_Type_free(&type_); }
  LegType(const LegType&) = delete;
  LegType& operator=(const LegType&) = delete;
  MPI_Datatype get() const { return type_; }

 private:
  MPI_Datatype type_ = MPI_DATATYPE_NULL;
};

// Closes one phase after another: its time since the last close, and the exchange time it added.
class PhaseClock {
 public:
  explicit PhaseClock(const ExchangeStats* exchange)
      : exchange_(exchange), start_(MPI_Wtime()), waited_(exchange->exchange_ms) {}
  void close(RenderPhase& phase) {
    const double now = MPI_Wtime();
    phase.ms = (now - start_) * 1e3;
    phase.wait_ms = exchange_->exchange_ms - waited_;
    start_ = now;
    waited_ = exchange_->exchange_ms;
  }

 private:
  const ExchangeStats* exchange_;
  double start_, waited_;
};

}  // namespace

Image render(MPI_Comm comm, const SlabPartition& partition, const World& world,
             const RenderSceneOptions& scene_options, const Camera& camera,
             const RenderOptions& options, RenderStats* stats, ExchangeStats* exchange_stats,
             RenderPhases* phases) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const Box3i whole = partition.domain;
  // The phases' waits are the exchange time each adds, so the exchange is always counted.
  ExchangeStats own_exchange;
  ExchangeStats* exchange = exchange_stats ? exchange_stats : &own_exchange;
  RenderPhases timed;
  PhaseClock clock(exchange);
  // Everything that can be refused is, before any field is computed.
  detail::collectively(comm, exchange, [&] {
    detail::require_partition(comm, partition);
    check_relay_frame(whole, partition.slab(rank), world.voxels.chunk_edge(), scene_options,
                      options);
  });
  const DistanceField skip = compute_distance_field(
      comm, partition, world.voxels, relay_skip_field_options(scene_options, whole), exchange);
  clock.close(timed.skip);
  // The part's lighting field and scene, then its stretches of the primary rays, agreed on once:
  // the ranks differ in each (the first follows the content of their slabs, the second where the
  // rays cross them), and a rank slower in one need not be slower in both.
  std::unique_ptr<RelayFrame> part;
  std::vector<RelayHit> first;
  const std::vector<RelayHit>& hits_here = *detail::collectively(comm, exchange, [&] {
    part = std::make_unique<RelayFrame>(world, whole, partition.slab(rank), skip, scene_options,
                                        camera, options);
    const std::vector<RelayHit>& hits = part->start();
    first.resize(hits.size());
    return &hits;
  });
  clock.close(timed.scene);
  const LegType leg_type;
  {
    detail::CollectiveTimer timer(exchange);
    MPI_Allreduce(hits_here.data(), first.data(), static_cast<int>(hits_here.size()),
                  MPI_DOUBLE_INT, MPI_MINLOC, comm);
  }
  clock.close(timed.first_hits);
  std::vector<RayLeg> legs =
      detail::collectively(comm, exchange, [&] { return part->start_shadows(first); });
  for (;;) {
    std::uint64_t mine = legs.size(), in_flight = 0;
    {
      detail::CollectiveTimer timer(exchange);
      MPI_Allreduce(&mine, &in_flight, 1, MPI_UINT64_T, MPI_SUM, comm);
    }
    if (in_flight == 0) break;
    const std::vector<RayLeg> in = route(comm, partition, legs, leg_type.get(), exchange);
    legs = detail::collectively(comm, exchange, [&] { return part->walk(in); });
    ++timed.relay_rounds;
  }
  clock.close(timed.shadows);
  const std::vector<double>& ends = part->shadows();
  std::vector<double> shadow =
      detail::collectively(comm, exchange, [&] { return std::vector<double>(ends.size()); });
  {
    detail::CollectiveTimer timer(exchange);
    MPI_Allreduce(ends.data(), shadow.data(), static_cast<int>(ends.size()), MPI_DOUBLE, MPI_MIN,
                  comm);
  }
  const std::vector<std::uint8_t> rgba =
      detail::collectively(comm, exchange, [&] { return part->shade(shadow); });
  std::vector<std::uint8_t> frame_rgba = detail::collectively(
      comm, exchange, [&] { return std::vector<std::uint8_t>(rank == 0 ? rgba.size() : 0); });
  {
    detail::CollectiveTimer timer(exchange);
    MPI_Reduce(rgba.data(), frame_rgba.data(), static_cast<int>(rgba.size()), MPI_UINT8_T, MPI_MAX,
               0, comm);
  }
  if (exchange) {
    exchange->bytes_sent +=
        hits_here.size() * sizeof(RelayHit) + ends.size() * sizeof(double) + rgba.size();
    exchange->bytes_received +=
        first.size() * sizeof(RelayHit) + ends.size() * sizeof(double) + frame_rgba.size();
  }
  if (stats) *stats = part->stats();
  // (Agreed on too: a rank 0 that failed here would leave the others waiting in the caller's next
  // collective call.)
  Image frame = detail::collectively(
      comm, exchange, [&] { return rank == 0 ? part->finish(frame_rgba) : Image{}; });
  clock.close(timed.shade);
  if (phases) *phases = timed;
  return frame;
}

}  // namespace voxfield::mpi
