// voxfield — exact distance fields of volumes split over the processes of an MPI job.
//
// Each rank owns a slab of z-slices of the domain (SlabPartition) and holds only that slab of the
// world and of the field. The exact transform's first pass runs along z, so a slab needs from the
// others only each column's nearest solid and air voxel below and above it (distance_slab.h): two
// exclusive scans over the ranks of 16 bytes per column, whatever the clamp or metric, and the
// result equals compute_distance_field over the whole domain bit for bit.
//
// Every function here that takes a communicator is collective over it: all ranks call it with the
// same arguments (their own occupancy and world aside). partition_slabs, edit_ghost_slices and
// SlabEditor::apply are local. A failure on any rank — a bad file, a memory limit, bad
// options — is agreed on before anything is written, and every rank then throws RankError naming
// the first failing rank and its message, so no rank waits forever on a collective the failed one
// never reaches. A rank that dies outright (a signal) is Open MPI's to report: mpirun ends the job.
//
// The communicator is the caller's (MPI_COMM_WORLD or a sub-communicator); MPI must be initialised
// (with at least MPI_THREAD_FUNNELED: only the calling thread talks to MPI, voxfield's thread pool
// works between the calls).
#pragma once

#include <mpi.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/distance_executor.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/edit.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/mesh.h"
#include "voxfield/render.h"
#include "voxfield/world.h"

namespace voxfield::mpi {

// Rank r owns the slices [z[r], z[r + 1]) of the domain, the whole x-y extent.
struct SlabPartition {
  Box3i domain;
  std::vector<std::int32_t> z;  // ranks + 1 cut points, z.front() = domain.begin.z, z.back() = end

  int ranks() const { return static_cast<int>(z.size()) - 1; }
  Box3i slab(int rank) const;
};

// Slabs of near-equal volume: cuts at multiples of `align` slices (the chunk edge, so that no chunk
// is split between ranks) when every rank can get at least one unit of `align`, else at single
// slices. Throws InvalidArgument when the domain has fewer slices
// than ranks (every rank must own one) or is empty.
SlabPartition partition_slabs(const Box3i& domain, int ranks, int align = 1);

// The units partition_slabs cuts at: `align` slices each from the first multiple of `align` at or
// below the domain's start, clipped to the domain (the first and last may be thinner).
std::vector<Box3i> slab_units(const Box3i& domain, int align);
// Slabs of near-equal weight (unit_weights[k] >= 0: the work in slab_units(domain, align)[k]),
// cut at unit boundaries, every rank keeping at least one unit: a terrain's surface, or the edits
// of a script, lie in a few units that slabs of equal volume would hand to one or two ranks. With
// fewer units than ranks, or no weight at all, the slabs of equal volume. InvalidArgument also for
// weights not one per unit, negative or not finite.
SlabPartition partition_slabs(const Box3i& domain, int ranks, int align,
                              const std::vector<double>& unit_weights);

// What a rank failed with, thrown on every rank of a collective operation that failed on any.
class RankError : public Error {
 public:
  RankError(int rank, const std::string& message)
      : Error("rank " + std::to_string(rank) + ": " + message), rank_(rank), message_(message) {}
  int rank() const { return rank_; }
  // The failing rank's message alone.
  const std::string& message() const { return message_; }

 private:
  int rank_;
  std::string message_;
};

struct ExchangeStats;

// Collective: returns when no rank failed (`error` empty on every rank); else every rank throws
// RankError with the lowest failing rank's message.
void agree(MPI_Comm comm, const std::string& error, ExchangeStats* stats = nullptr);

// Runs fn() on this rank and agrees with every rank on the outcome: fn's result when no rank
// failed, else the same RankError on every rank (a RankError fn throws — agreed inside it — passes
// through). For a rank's own work between collective calls: a loop of edits, a file of its own.
template <class Fn>
auto collectively(MPI_Comm comm, Fn&& fn, ExchangeStats* stats = nullptr) {
  using R = std::invoke_result_t<Fn>;
  std::string error;
  if constexpr (std::is_void_v<R>) {
    try {
      fn();
    } catch (const RankError&) {
      throw;
    } catch (const std::exception& e) {
      error = e.what();
    }
    agree(comm, error, stats);
  } else {
    std::optional<R> result;
    try {
      result.emplace(fn());
    } catch (const RankError&) {
      throw;
    } catch (const std::exception& e) {
      error = e.what();
    }
    agree(comm, error, stats);
    return std::move(*result);
  }
}

// Counters of one rank's part of a collective computation.
struct ExchangeStats {
  std::uint64_t bytes_sent = 0;      // payload this rank contributed to the exchanges
  std::uint64_t bytes_received = 0;  // payload it received
  int collectives = 0;               // collective calls made (scans, reductions, broadcasts)
  double exchange_ms = 0;            // in those calls (waiting for slower ranks included)
  double compute_ms = 0;             // in this rank's own transform
};

// The exact field of the whole partition.domain, this rank's slab of it: `occupancy` (non-zero =
// solid) must hold this rank's slab (voxels outside it are not read); `options.domain` is ignored
// (the partition's domain is the field's). The returned field's domain is the slab; its values and
// nearest sites equal compute_distance_field's over the whole domain for those voxels.
DistanceField compute_distance_field(MPI_Comm comm, const SlabPartition& partition,
                                     const Grid<std::uint8_t>& occupancy,
                                     const DistanceOptions& options,
                                     ExchangeStats* stats = nullptr);

// The same field with each rank's slab computed on `executor`: that rank's own device (each
// process of a job on a GPU node takes its own Executor) or the CPU
// (compute_slab_distance_field in distance_executor.h). `world` holds this rank's slab. Equal to
// the CPU's as the GPU's fields are (gpu_distance.h): bit for bit in integer storage. A rank whose
// device refuses the options (a work buffer it cannot bind, anisotropic spacing) fails every rank
// with its message.
DistanceField compute_distance_field(MPI_Comm comm, const SlabPartition& partition,
                                     const World& world, const DistanceOptions& options,
                                     const Executor& executor, ExchangeStats* stats = nullptr);

// Edits. Every rank applies every edit (an edit script or a seeded stream is small, and the same on
// all ranks) to its slab and to `edit_ghost_slices` slices on either side, and updates its own
// incremental field (dynamic_field.h) over that box: a clamped value depends only on sites within
// the clamp, so the slab's values stay exact — equal to one process's field after the same edits —
// with no message per edit. An edit that misses a rank's box costs that rank nothing. An unclamped
// f32 value may depend on every voxel of the domain: each rank then keeps its slab (and no more
// slices than the caller asks it to keep), edits change its materials, and SlabEditor::refresh
// recomputes the field over the ranks.

// The slices a rank's box reaches past its slab on either side: the effective clamp over the
// spacing along z, rounded up (distance_slab.h); 0 for an unclamped f32 field (kept by refresh()).
int edit_ghost_slices(const DistanceOptions& options);

// Per unit of slab_units(domain, align): the work a script's edits bring it, for partition_slabs —
// each edit's brush box grown by `ghost_slices` on every side (what its field update may
// recompute), clipped to the domain, counted in voxels within the unit. Local (every rank computes
// the same from the same script).
std::vector<double> edit_unit_weights(const Box3i& domain, int align,
                                      const std::vector<Edit>& edits, int ghost_slices);

// A rank's slab of a world and its exact field, kept under edits. Constructing is collective (it
// agrees on failures; a clamped field is computed then, an unclamped f32 one by the first
// refresh()); apply() is local to the rank and may be called any number of times between
// collective calls; refresh() is collective.
class SlabEditor {
 public:
  // `world` must hold the partition's slab of this rank grown by edit_ghost_slices along z (clipped
  // to the domain); what lies beyond is not read. The field is computed over that box, on
  // `executor` (this rank's device or the CPU: an IncrementalDistanceField, distance_executor.h).
  // `kept_slices`: the world keeps (and edits) at least that many slices beyond the slab on either
  // side, for what the caller reads from it afterwards — a surface meshed from the edited world
  // (mesh_world_slab_reach) — and `world` must then hold them too. A clamped field is computed
  // over that whole box; an unclamped one over the slab (refresh() reads the slab's voxels only).
  SlabEditor(MPI_Comm comm, const SlabPartition& partition, const World& world,
             const DistanceOptions& options, const Executor& executor = {}, int kept_slices = 0);
  SlabEditor(const SlabEditor&) = delete;  // the field is bound to the world it holds
  SlabEditor& operator=(const SlabEditor&) = delete;

  struct Result {
    std::int64_t voxels_changed = 0;     // in this rank's box
    std::int64_t voxels_recomputed = 0;  // by this rank's field update (0 when refresh() does it)
    bool reached = false;                // whether the edit touched this rank's box
  };
  // Applies the edit clipped to this rank's box and updates a clamped field (an unclamped one
  // waits for refresh()). Throws what apply_edit throws (a malformed edit: on every rank alike).
  Result apply(const Edit& edit);
  // Collective: brings an unclamped f32 field up to date with the edits applied since the last
  // refresh — one exact transform over the ranks (compute_distance_field above) on the first call
  // and whenever an edit changed the solids of any rank's slab since; nothing when none did, or for
  // a clamped field, which apply() keeps exact. Returns whether the field was recomputed; `voxels`
  // (if given) counts the slab's voxels recomputed here. On a failure (RankError on every rank) the
  // field is gone until a refresh succeeds.
  bool refresh(MPI_Comm comm, ExchangeStats* stats = nullptr, std::int64_t* voxels = nullptr);
  // Whether field() waits on refresh(): an unclamped field not yet computed, or with solids changed
  // since.
  bool stale() const { return stale_; }

  // The rank's field over its box; its values over slab() are the whole field's (an unclamped
  // field's as of the last refresh(); InvalidArgument before one has succeeded). A clamped field on
  // a device is read back by the first call after a change (bytes moved; it may throw what a
  // device throws, on this rank alone: call it inside mpi::collectively), and the reference is
  // valid until the next apply() or refresh(). Not thread-safe.
  const DistanceField& field() const;
  const World& world() const { return world_; }
  Box3i slab() const { return slab_; }
  Box3i box() const { return box_; }

 private:
  Box3i slab_, box_;
  World world_;
  SlabPartition partition_;
  DistanceOptions options_;
  Executor executor_;
  std::unique_ptr<IncrementalDistanceField> field_;  // a clamped field, kept by apply()
  std::optional<DistanceField> whole_;               // an unclamped one, kept by refresh()
  bool stale_ = false;
  DirtyRegions dirty_;
};

// Who opens a world file load_world_slab reads: every rank (a shared file system), or rank 0
// alone, which sends the others what they need (load_world_slab says what).
enum class ReadBy { kEveryRank, kRankZero };

// How load_world_slab reads a world file.
struct SlabReadOptions {
  ReadBy read_by = ReadBy::kEveryRank;
  // A .vdb input's grid, by name (LoadOptions::vdb_grid: by default voxfield's world grid, else
  // the first int32 grid, else the first); InvalidArgument for another format.
  std::string vdb_grid;
};

// A rank's slab of a world file.
struct WorldSlab {
  World world;  // the slab's voxels and its ghost slices, at their place in the whole world
  SlabPartition partition;
  std::string format;  // "npy", "vox", "vfw" or "vdb"
  // Each rank built only its slab: a .npy's part read alone, a .vfw's chunks decompressed alone,
  // a .vox's voxels placed within the slab alone, a .vdb's leaves decoded within the slab alone
  // (the file read by every rank, or its bytes sent by rank 0). Every format voxfield reads is
  // read so.
  bool read_in_parts = false;
  ReadBy read_by = ReadBy::kEveryRank;
};

// Loads `path` for this rank, keeping its slab and `ghost_slices` slices on either side: a .npy is
// read a part per rank (read_npy_part), so no rank ever holds more; a .vfw is read as compressed
// bytes by every rank, which decompresses only its slab's chunks (WorldFileReadOptions::keep_z) —
// the file's size plus the slab per rank. An unbounded .vfw's domain is its content's bounds: each
// rank first decodes an equal share of the z-range its stored chunks cover and the ranks unite what
// they find. A .vox is read by every rank, which places only its slab's voxels
// (VoxImportOptions::keep_z) — the file, its models' voxel lists and the slab per rank; its scene
// is read twice (described, then placed), the extent coming first. A .vdb is read by every rank,
// which decodes only the tiles and leaves of its slab (VdbReadOptions::clip: the others' values
// are stepped over undecoded); its domain, voxfield's recorded extent united with the solid
// voxels, comes from an equal z-share of the tree's stored bounds decoded by each rank first. The
// domain is the file's volume (the .npy shape, the .vox/.vfw/.vdb extent), as `voxfield field`
// uses.
//
// `read.read_by` kRankZero is the fallback for ranks that cannot see rank 0's files (no shared file
// system): rank 0 alone opens the file. A .npy's parts are read by rank 0 one rank at a time and
// each sent to its rank (rank 0 holds one part at a time, its own last); a .vfw's,
// .vox's or .vdb's bytes (compressed, or a list of voxels: small beside the world) are broadcast,
// and each rank decodes its own slab of them as above. The slabs are the same either way. Every
// transfer is agreed on first: a rank that cannot hold what it would receive fails every rank
// with its reason.
WorldSlab load_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                          int ghost_slices = 0, const SlabReadOptions& read = {});
// The same with the slabs cut by cut(domain) once the domain is known (every rank must cut it
// alike; InvalidArgument unless it is a partition of that domain into the communicator's ranks):
// slabs weighed by content (content_unit_weights) or by a script's edits (edit_unit_weights).
using SlabCut = std::function<SlabPartition(const Box3i& domain)>;
WorldSlab load_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                          int ghost_slices, const SlabCut& cut, const SlabReadOptions& read = {});
// The same with the slabs weighed by content, for work that follows the surface (a script's edits,
// which land on it; a field's own work follows the volume, docs/mpi.md): read first in slabs of
// equal volume, the ranks count where the surface lies (content_unit_weights, on `chunk_edge`),
// let go of that reading, and read the world again in slabs of equal weight. Twice the reading;
// the same world, cut elsewhere.
WorldSlab load_world_slab_by_content(MPI_Comm comm, const std::filesystem::path& path,
                                     int chunk_edge, int ghost_slices = 0,
                                     const SlabReadOptions& read = {});

// Collective: per unit of slab_units(partition.domain, align), the chunks of the ranks' worlds
// within the unit's slices that hold both air and solid voxels (where a world's surface lies, and
// the edits of it land; a chunk of two materials is not one) plus a 64th of all its chunks (every
// chunk's field is computed, surface or not). Each
// rank counts the chunks of its own slab of `world` (chunked on `align`); the ranks sum them.
std::vector<double> content_unit_weights(MPI_Comm comm, const SlabPartition& partition,
                                         const World& world, int align,
                                         ExchangeStats* stats = nullptr);

// What write_field_npy writes.
struct FieldFiles {
  // a[x, y, z] of the stored values (uint8, uint16 or float32); empty: not written (a .vdb
  // written by encode_vdb_field below instead)
  std::filesystem::path values;
  std::filesystem::path sites;  // optional: int16 a[x, y, z, 3] nearest-site offsets
  std::filesystem::path json;   // optional: written by rank 0 with `json_text`
  std::string json_text;
  // Optional: the dissertation's packed uint32 voxels (dissertation_format.h) of `world`, this
  // rank's world holding at least its slab, with the field's distances; and the world's
  // materials, uint8 a[x, y, z] over the domain (the .npy save_world writes).
  std::filesystem::path packed;
  const World* world = nullptr;
  std::filesystem::path materials;
};

// Checks the targets (empty paths skipped) as check_output_path does, on rank 0 whose view of the
// file system writes them, before any work: every rank throws RankError when one cannot be
// written. `shared` targets, which every rank writes into (the .npy and .vfw outputs), must also be
// regular files or new ones; `rank0` ones (a JSON file) may be standard output. No two targets may
// name one file (the later would replace the earlier), nor any of `inputs`.
void check_outputs(MPI_Comm comm, const std::vector<std::filesystem::path>& shared,
                   const std::vector<std::filesystem::path>& rank0 = {},
                   const std::vector<std::filesystem::path>& inputs = {});

// Writes every rank's slab of the field (a field covering at least the rank's slab: its values over
// the slab are written) into one .npy per output, byte for byte what `voxfield
// field` writes for the whole domain, all or nothing: rank 0 stages temporaries beside the targets
// (FileTransaction::stage_shared), every rank writes its slices into them with MPI-IO, and only
// when all ranks succeeded does rank 0 rename them onto the targets. On failure no target is
// touched and the temporaries are removed.
// `into`: rank 0's transaction to stage the outputs in, for the caller to commit with others
// (collectively); null (and on other ranks): its own, committed before returning.
void write_field_npy(MPI_Comm comm, const SlabPartition& partition, const DistanceField& slab,
                     const FieldFiles& files, ExchangeStats* stats = nullptr,
                     FileTransaction* into = nullptr);

// Collective: the field the ranks hold in slabs as the bytes of one .vdb file on rank 0 (empty on
// the others) — the bytes `voxfield field -o F.vdb` (encode_vdb_field, vdb.h) writes for the whole
// field. Each rank encodes its slab's grid with the whole field's background (the largest of the
// ranks' vdb_field_background) and sends it to rank 0, one rank at a time; rank 0 joins them
// (VdbFieldParts). Rank 0 so holds the whole grid: the narrow band of a clamped field (active where
// |distance| is below the clamp), every voxel of an unclamped one; each part's room on rank 0 is
// agreed on before it moves (ResourceLimitError on every rank past rank 0's memory limit). `slab`:
// this rank's field over exactly its slab (compute_distance_field's), in the world's frame.
std::vector<std::uint8_t> encode_vdb_field(MPI_Comm comm, const SlabPartition& partition,
                                           const DistanceField& slab,
                                           ExchangeStats* stats = nullptr);

// Writes the world of every rank's slab into one .vfw world file (docs/formats.md), byte for byte
// what one process writes for the whole world bounded to the partition's domain (`voxfield edit
// --save-world`, `voxfield convert`), all or nothing as write_field_npy: each rank encodes the
// chunks of its slab and writes them at its place, rank 0 the header and checksum, and renames the
// file once every rank has written. `world` must hold this rank's slab (chunks of other slabs it
// holds are not written); the slabs must be cut on chunk boundaries (InvalidArgument otherwise:
// partition_slabs with the chunk edge as `align` does so when the domain has a chunk layer for
// every rank).
// `into` as for write_field_npy.
void save_world_vfw(MPI_Comm comm, const SlabPartition& partition, const World& world,
                    const std::filesystem::path& path, ExchangeStats* stats = nullptr,
                    FileTransaction* into = nullptr);

// The bounds of the world's content (voxels that are not air) over every rank's slab — ghost
// slices count once, in the slab that owns them: what a camera frames.
Box3i content_bounds(MPI_Comm comm, const SlabPartition& partition, const World& world);

// One rank's frame of mpi::render, phase by phase: each phase's time on this rank from its start
// to the end of the collective call that closes it, and of that the time spent inside collective
// calls (waiting for slower ranks included) — so ms - wait_ms is the rank's own work, and a rank
// whose waits are long has less to do than another in that phase.
struct RenderPhase {
  double ms = 0;
  double wait_ms = 0;
};
struct RenderPhases {
  RenderPhase skip;        // the skip field over the ranks (compute_distance_field)
  RenderPhase scene;       // the lighting field, the part's scene, its stretches of primary rays
  RenderPhase first_hits;  // every pixel's first hit agreed (MPI_MINLOC)
  RenderPhase shadows;     // the shadow rays started and relayed to the slabs they enter
  RenderPhase shade;       // shadows agreed, pixels shaded, the frame composited on rank 0
  int relay_rounds = 0;    // rounds of the shadow relay
};

// Frames of the world the ranks hold in slabs, drawn where it lies (render_relay.h): every rank
// walks its stretch of every primary ray at once, the first hit along each ray is the pixel's
// (MPI_MINLOC), and the shadow rays of those hits are relayed, each sent on to the rank whose slab
// it enters; each pixel is shaded by the rank where its primary ray first hit. Rank 0 returns
// the frame — render(RenderScene(whole world, scene_options, partition.domain), camera, options)
// byte for byte, for a world whose content lies within the domain — and the others an empty
// image. `world` must hold the rank's relay_world_box (its slab and relay_ghost_slices slices on
// either side along z: load_world_slab's ghost_slices), the slabs cut on the world's chunk
// boundaries (partition_slabs with the chunk edge when the domain has a chunk layer per rank). The
// skip field is computed over the ranks (compute_distance_field above), the lighting field by each
// rank over its slab and ghost slices. Views: shaded, chunks and distance (the cut drawn by the
// rank holding its slice). `stats`: this rank's walks (a
// ray counts once per rank that walked a stretch of it); `phases`: where its time went.
Image render(MPI_Comm comm, const SlabPartition& partition, const World& world,
             const RenderSceneOptions& scene_options, const Camera& camera,
             const RenderOptions& options, RenderStats* stats = nullptr,
             ExchangeStats* exchange = nullptr, RenderPhases* phases = nullptr);

// Meshes of a lattice no rank holds whole (a scan or a simulation's float volume, a distributed
// field). The lattice's chunk layers (mesh_pieces.h: the chunked mesher's chunks grouped along z)
// are dealt to the ranks in runs of near-equal length or weight; each rank meshes its run from the
// sample planes that run reads — its cells' planes, three below and two above. Every mesher
// without an analytic value or gradient (mesh_slab_applies): each rank meshes its run's planes as
// a slab in the whole-volume passes (mesh_slab.h), and the mesh equals mesh_volume(volume,
// options) — what one process makes — array for array. With one: rank 0 joins the pieces with the
// chunked mesher's weld, and the mesh equals MeshChunks(volume, options).merged() array for array
// (and mesh_volume's triangle for triangle). Either for any number of ranks; write_mesh_volume
// writes it with each rank writing its share of the file, nothing gathered.

// Rank r meshes chunk layers [layers[r], layers[r + 1]).
struct MeshLayers {
  Vec3i samples;  // the whole lattice's
  int chunk_edge = 32;
  std::vector<std::int32_t> layers;  // ranks + 1 cut points

  int ranks() const { return static_cast<int>(layers.size()) - 1; }
  bool empty(int rank) const;  // a rank past the layers' count has none
  // The sample planes [first, second) rank `rank` must hold: what its layers read ([0, 0) when it
  // has none).
  std::pair<int, int> planes(int rank) const;
  // The sample planes [first, second) whose rows rank `rank`'s slab owns when meshing by slabs
  // (mesh_slab.h): its layers' cell planes, and the lattice's last plane for the last rank with
  // layers ([0, 0) when it has none).
  std::pair<int, int> slab(int rank) const;
};

// Runs of ceil or floor(layers / ranks) layers, in rank order. InvalidArgument for a lattice under
// 2 samples along an axis or a chunk edge outside 2..256.
MeshLayers partition_mesh_layers(Vec3i samples, int chunk_edge, int ranks);
// Runs of near-equal total weight (layer_weights[k] >= 0: layer k's work), in rank order: a
// terrain's surface lies in a few layers, which equal counts would hand to one or two ranks.
// InvalidArgument also for weights not one per layer, negative or not finite.
MeshLayers partition_mesh_layers(Vec3i samples, int chunk_edge, int ranks,
                                 const std::vector<double>& layer_weights);

// Collective: each chunk layer's meshing work, for partition_mesh_layers: the lattice edges within
// its sample planes that the iso-surface crosses (what its triangles follow) plus a 64th of its
// samples (every sample is classified, surface or not). Rank r passes the samples of planes
// [z0, z1) of the lattice (x fastest) — any split of the planes among the ranks, each plane passed
// by exactly one (InvalidArgument on every rank otherwise). Options as for mesh_volume.
std::vector<double> mesh_layer_weights(MPI_Comm comm, Vec3i samples, int z0, int z1,
                                       const float* planes, const MeshOptions& options,
                                       ExchangeStats* stats = nullptr);

// Collective: meshes the lattice `frame` describes (its size, origin and spacing; frame.values is
// not read) with `options` (options.chunk_edge must be layers.chunk_edge). Each rank passes
// `planes`: the samples of layers.planes(rank), x fastest (null on a rank without layers). Returns
// the whole mesh on rank 0 and an empty one on the others. Rank 0 must hold the mesh and every
// piece; pieces travel in messages of at most 256 MiB. Throws RankError on every rank when any
// fails (a NaN sample, the memory limit, mismatched options).
Mesh mesh_volume(MPI_Comm comm, const MeshLayers& layers, const ScalarVolume& frame,
                 const float* planes, const MeshOptions& options, ExchangeStats* stats = nullptr);

// What write_mesh_volume wrote: the joined mesh's counts and, when asked for, its census.
struct MeshFileSummary {
  std::uint64_t vertices = 0, triangles = 0;
  // mesh_stats of the joined mesh: every count equal; area and volume summed over the ranks in
  // another order, so equal within rounding.
  std::optional<MeshStats> census;
  double census_ms = 0;  // this rank's time in the census (a part of the call's)
};

// Collective: meshes as mesh_volume does and writes the mesh to `path` (the format its extension
// names, mesh_files.h) with no rank ever holding more than its own share of it. By slabs: each
// rank's slab is one run of the mesh's vertices and triangles (an exclusive scan numbers them).
// By pieces (an analytic value or gradient): each rank welds its piece with what its neighbours
// lend it (PieceWeld: vertex numbers across the cuts, orphans first used before its layers). Each
// rank writes its vertices and triangles at their places in the file: the bytes write_mesh writes
// for mesh_volume's mesh (the one process's mesh named above), atomically (staged beside the target
// by rank 0, renamed once every rank has written; a failure anywhere leaves the target as it
// was). `census` (the same on every rank): also mesh_stats over the ranks (each edge the cuts split
// counted by the rank holding its lower vertex). `into` (rank 0's; null on the others): the file is
// staged in the caller's transaction and the caller commits it (collectively); null: committed
// before returning. Throws RankError on every rank when any fails.
MeshFileSummary write_mesh_volume(MPI_Comm comm, const MeshLayers& layers,
                                  const ScalarVolume& frame, const float* planes,
                                  const MeshOptions& options, const std::filesystem::path& path,
                                  bool census = false, ExchangeStats* stats = nullptr,
                                  FileTransaction* into = nullptr);

// Collective: a voxel world's surface (mesh_world at iso 0, mesh.h) written to `path` as
// write_mesh_volume writes a float volume's — the bytes write_mesh writes for mesh_world(the whole
// world, options, metric), each rank writing its share, nothing gathered. `lattice` is
// mesh_world's: the world's content bounds over the ranks (content_bounds above) grown by
// mesh_world_margin(0); `layers` are cut for its size (partition_mesh_layers(lattice.size(), ...)),
// or are of edge 1 — every cell plane a layer, so that the ranks' rows may be cut anywhere (as the
// slabs of an edited world lie) — whatever options.chunk_edge. Each rank's `world` holds, with the
// world's palette and frame, at least the slices mesh_world_slab_voxels(lattice, s0, s1,
// options.algorithm) names for its rows [s0, s1) = layers.slab(rank) (mesh_slab.h; the dual
// meshers read more below than marching cubes): each computes the exact signed field of the
// planes it meshes from them.
// Throws RankError on every rank when any fails (an offset surface, iso != 0, is refused: its
// normals come from nearest voxels in any slab).
MeshFileSummary write_world_mesh(MPI_Comm comm, const MeshLayers& layers, const Box3i& lattice,
                                 const World& world, const MeshOptions& options, Metric metric,
                                 const std::filesystem::path& path, bool census = false,
                                 ExchangeStats* stats = nullptr, FileTransaction* into = nullptr);

}  // namespace voxfield::mpi
