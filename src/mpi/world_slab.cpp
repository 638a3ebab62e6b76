// voxfield — a rank's slab of a world file (mpi.h): .npy arrays read a part per rank, .vfw, .vox
// and .vdb files decoded a slab per rank.
#include <mpi.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <optional>

#include "collective.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/npy.h"
#include "voxfield/vdb.h"
#include "voxfield/vox.h"
#include "voxfield/world_file.h"
#include "voxfield/world_io.h"

namespace voxfield::mpi {

namespace {

// This rank's slab of `domain`'s partition and `ghost` slices on either side, within the domain.
Box3i kept_box(const Box3i& domain, const SlabPartition& partition, int rank, int ghost) {
  const Box3i slab = partition.slab(rank);
  const std::int64_t g = std::max(ghost, 0);
  return {{domain.begin.x, domain.begin.y,
           static_cast<std::int32_t>(std::max<std::int64_t>(domain.begin.z, slab.begin.z - g))},
          {domain.end.x, domain.end.y,
           static_cast<std::int32_t>(std::min<std::int64_t>(domain.end.z, slab.end.z + g))}};
}

// This rank's equal share of `box` along z (what it decodes to help bound a domain).
Box3i z_share(const Box3i& box, int rank, int ranks) {
  const std::int64_t z0 = box.begin.z, slices = box.size().z;
  Box3i share = box;
  share.begin.z = static_cast<std::int32_t>(z0 + slices * rank / ranks);
  share.end.z = static_cast<std::int32_t>(z0 + slices * (rank + 1) / ranks);
  return share;
}

// cut(domain), checked to be a partition of that domain into `ranks` slabs.
SlabPartition checked_cut(const SlabCut& cut, const Box3i& domain, int ranks) {
  SlabPartition p = cut(domain);
  bool ok = p.domain == domain && p.ranks() == ranks && p.z.front() == domain.begin.z &&
            p.z.back() == domain.end.z;
  for (std::size_t r = 1; ok && r < p.z.size(); ++r) ok = p.z[r] > p.z[r - 1];
  if (!ok)
    throw InvalidArgument("load_world_slab: the slabs cut for " + to_string(domain) +
                          " are not a partition of it into " + std::to_string(ranks) +
                          " non-empty slabs");
  return p;
}

// A .vfw: every rank holds the compressed bytes and decodes only its slab's chunks (every checksum
// and world chunk record still checked). A bounded world's domain is in the file's head. An
// unbounded one's is its content's bounds, as `voxfield field` takes them: the chunk records say
// which z-range may hold content (WorldFile::stored_chunks_box), each rank decodes an equal share
// of it and bounds what it finds, and the union of the ranks' bounds is the domain — so no rank
// ever decodes more than about two slabs, whatever the world's size.
WorldSlab vfw_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge, int ghost,
                   const SlabCut& cut, std::vector<std::uint8_t>* sent) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  struct Head {
    std::vector<std::uint8_t> bytes;
    WorldFileReadOptions options;
    std::optional<Box3i> bounds;
    Box3i content;  // of this rank's share of an unbounded world's stored chunks
  };
  Head h = detail::collectively(comm, nullptr, [&] {
    Head out;
    const std::uint64_t limit = effective_memory_limit(0);
    out.bytes = sent ? std::move(*sent) : read_file(path, limit);
    out.options.memory_limit_bytes = remaining_memory(limit, out.bytes.size());
    out.options.keep_z = std::pair<std::int32_t, std::int32_t>{0, 0};
    const WorldFile head = parse_world_file(out.bytes, path.string(), out.options);
    out.bounds = head.world.voxels.bounds();
    const Box3i stored = head.stored_chunks_box;
    if (!out.bounds && !stored.empty()) {
      const Box3i mine = z_share(stored, rank, size);
      WorldFileReadOptions share = out.options;
      share.keep_z = std::pair<std::int32_t, std::int32_t>{mine.begin.z, mine.end.z};
      out.content = parse_world_file(out.bytes, path.string(), share).world.voxels.content_bounds();
    }
    return out;
  });
  // (Every rank takes part in the union, bounded file or not: a collective call must not depend
  // on what each rank read.)
  const Box3i content = detail::unite_over_ranks(comm, h.content, nullptr);
  const Box3i domain = h.bounds ? *h.bounds : content;
  return detail::collectively(comm, nullptr, [&] {
    if (domain.empty()) throw InvalidArgument(path.string() + ": the input holds no volume");
    const SlabPartition partition = checked_cut(cut, domain, size);
    const Box3i keep = kept_box(domain, partition, rank, ghost);
    WorldFileReadOptions slab_only = h.options;
    slab_only.keep_z = std::pair<std::int32_t, std::int32_t>{keep.begin.z, keep.end.z};
    const WorldFile part = parse_world_file(h.bytes, path.string(), slab_only);
    World world = rechunk_world(part.world, chunk_edge, keep, path.string());
    return WorldSlab{std::move(world), partition, "vfw", true};
  });
}

// A .vdb: every rank holds the file's bytes and decodes only the leaves and tiles of its slab
// (VdbReadOptions::clip; the others' values are stepped over). The domain is voxfield's recorded
// extent united with the content, as `voxfield field` takes it: the tree's topology (read with an
// empty clip) bounds where content may lie, each rank decodes an equal z-share of that and bounds
// the solid voxels it finds, and the union over the ranks is the domain.
WorldSlab vdb_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge, int ghost,
                   const SlabCut& cut, const std::string& grid, std::vector<std::uint8_t>* sent) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  struct Head {
    std::vector<std::uint8_t> bytes;
    VdbReadOptions options;
    Box3i content;  // of this rank's share: the recorded extent and the solid voxels found
    std::optional<VdbWorld> whole;  // one rank's share is the whole tree: read once
  };
  const std::string name = path.string();
  auto world_in = [&](const Head& h, const Box3i& clip) {
    VdbReadOptions o = h.options;
    o.clip = clip;
    const VdbFile file = decode_vdb(h.bytes, name, o);
    return world_from_vdb(file, name, chunk_edge,
                          remaining_memory(o.memory_limit_bytes, file.memory_bytes()), grid);
  };
  Head h = detail::collectively(comm, nullptr, [&] {
    Head out;
    const std::uint64_t limit = effective_memory_limit(0);
    out.bytes = sent ? std::move(*sent) : read_file(path, limit);
    out.options.memory_limit_bytes = remaining_memory(limit, out.bytes.size());
    const VdbWorld topology = world_in(out, Box3i{});
    out.content = topology.extent;
    const Box3i stored = topology.stored;
    if (!stored.empty()) {
      const Box3i share = z_share(stored, rank, size);
      if (size == 1) {
        out.whole = world_in(out, stored);
        out.content = out.whole->extent;
      } else if (!share.empty()) {
        out.content = out.content.unite(world_in(out, share).extent);
      }
    }
    return out;
  });
  const Box3i domain = detail::unite_over_ranks(comm, h.content, nullptr);
  return detail::collectively(comm, nullptr, [&] {
    if (domain.empty()) throw InvalidArgument(name + ": the input holds no volume");
    const SlabPartition partition = checked_cut(cut, domain, size);
    const Box3i keep = kept_box(domain, partition, rank, ghost);
    const VdbWorld part = h.whole ? std::move(*h.whole) : world_in(h, keep);
    return WorldSlab{rechunk_world(part.world, chunk_edge, keep, name), partition, "vdb", true};
  });
}

// The fields that place a part of a .npy in its file, sent before its values (so a value refused
// on the receiving rank is named by its index and byte offset in the file, as when that rank reads
// it itself).
constexpr std::size_t kPartFields = 13;
std::vector<std::uint8_t> part_fields(const NpyVolume& part) {
  const std::array<std::int64_t, kPartFields> f{static_cast<std::int64_t>(part.dtype),
                                                part.dims.x,
                                                part.dims.y,
                                                part.dims.z,
                                                static_cast<std::int64_t>(part.file_data_offset),
                                                part.file_c_order ? 1 : 0,
                                                part.file_origin.x,
                                                part.file_origin.y,
                                                part.file_origin.z,
                                                part.file_dims.x,
                                                part.file_dims.y,
                                                part.file_dims.z,
                                                part.components};
  std::vector<std::uint8_t> out(sizeof f);
  std::memcpy(out.data(), f.data(), sizeof f);
  return out;
}
NpyVolume part_from(const std::vector<std::uint8_t>& fields, std::vector<std::uint8_t> values) {
  std::array<std::int64_t, kPartFields> f{};
  std::memcpy(f.data(), fields.data(), sizeof f);  // part_fields' bytes, from rank 0
  const auto i32 = [](std::int64_t v) { return static_cast<std::int32_t>(v); };
  NpyVolume part;
  part.dtype = static_cast<DType>(f[0]);
  part.dims = {i32(f[1]), i32(f[2]), i32(f[3])};
  part.file_data_offset = static_cast<std::uint64_t>(f[4]);
  part.file_c_order = f[5] != 0;
  part.file_origin = {i32(f[6]), i32(f[7]), i32(f[8])};
  part.file_dims = {i32(f[9]), i32(f[10]), i32(f[11])};
  part.components = static_cast<int>(f[12]);
  part.bytes = std::move(values);
  return part;
}

// A .npy read by rank 0 alone: its header's shape broadcast, then each rank's part (its slab and
// ghost slices) read by rank 0 and sent to it, one rank at a time.
WorldSlab npy_slab_from_rank_zero(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                                  int ghost, const SlabCut& cut) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  std::array<std::int32_t, 3> dims = detail::collectively(comm, nullptr, [&] {
    const Vec3i d = rank == 0 ? read_npy_header(path).dims : Vec3i{};
    return std::array<std::int32_t, 3>{d.x, d.y, d.z};
  });
  MPI_Bcast(dims.data(), 3, MPI_INT32_T, 0, comm);
  const Box3i domain = Box3i::from_size({dims[0], dims[1], dims[2]});
  const SlabPartition partition =
      detail::collectively(comm, nullptr, [&] { return checked_cut(cut, domain, size); });
  const auto part_of = [&](int r) {
    const Box3i keep = kept_box(domain, partition, r, ghost);
    return read_npy_part(path, keep.begin.z, keep.end.z);
  };
  // Rank 0 holds one part at a time: each other rank's, moved into its sends, then its own.
  std::vector<std::uint8_t> fields, values;
  for (int r = 1; r < size; ++r) {
    NpyVolume part =
        detail::collectively(comm, nullptr, [&] { return rank == 0 ? part_of(r) : NpyVolume{}; });
    std::vector<std::uint8_t> f =
        detail::send_bytes(comm, r, rank == 0 ? part_fields(part) : std::vector<std::uint8_t>{},
                           path.string(), nullptr);
    std::vector<std::uint8_t> v =
        detail::send_bytes(comm, r, std::move(part.bytes), path.string(), nullptr);
    if (rank == r) fields = std::move(f), values = std::move(v);
  }
  return detail::collectively(comm, nullptr, [&] {
    const NpyVolume part = rank == 0 ? part_of(0) : part_from(fields, std::move(values));
    return WorldSlab{world_from_npy(part, path.string(), chunk_edge), partition, "npy", true};
  });
}

WorldSlab read_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                          int ghost_slices, const SlabCut& cut, const SlabReadOptions& read) {
  int rank = 0, size = 0;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  // (The format is named by the extension alone: every rank agrees on it without a word.)
  const WorldFormat format = detail::collectively(comm, nullptr, [&] {
    const WorldFormat f = world_format_of(path);
    if (!read.vdb_grid.empty() && f != WorldFormat::kVdb)
      throw InvalidArgument(path.string() + ": a grid name ('" + read.vdb_grid +
                            "') is for .vdb files, which hold several grids");
    return f;
  });
  const bool from_zero = read.read_by == ReadBy::kRankZero;
  if (from_zero && format == WorldFormat::kNpy)
    return npy_slab_from_rank_zero(comm, path, chunk_edge, ghost_slices, cut);
  // The other formats' bytes, read by rank 0 and broadcast: each rank decodes its own slab of them.
  std::vector<std::uint8_t> sent;
  if (from_zero) {
    std::vector<std::uint8_t> bytes = detail::collectively(comm, nullptr, [&] {
      return rank == 0 ? read_file(path, effective_memory_limit(0)) : std::vector<std::uint8_t>{};
    });
    sent = detail::broadcast_bytes(comm, std::move(bytes), path.string(), nullptr);
  }
  std::vector<std::uint8_t>* const bytes_sent = from_zero ? &sent : nullptr;
  if (format == WorldFormat::kVfw)
    return vfw_slab(comm, path, chunk_edge, ghost_slices, cut, bytes_sent);
  if (format == WorldFormat::kVdb)
    return vdb_slab(comm, path, chunk_edge, ghost_slices, cut, read.vdb_grid, bytes_sent);
  return detail::collectively(comm, nullptr, [&] {
    if (format == WorldFormat::kNpy) {
      const NpyVolume head = read_npy_header(path);
      const Box3i domain = Box3i::from_size(head.dims);
      const SlabPartition partition = checked_cut(cut, domain, size);
      const Box3i keep = kept_box(domain, partition, rank, ghost_slices);
      World part =
          world_from_npy(read_npy_part(path, keep.begin.z, keep.end.z), path.string(), chunk_edge);
      return WorldSlab{std::move(part), partition, "npy", true};
    }
    // A .vox (the last of world_format_of's formats): read once; the scene described first
    // (nothing placed: its extent gives the slabs), then only this rank's slab and ghost slices
    // placed.
    const std::uint64_t limit = effective_memory_limit(0);
    const std::vector<std::uint8_t> bytes =
        bytes_sent ? std::move(*bytes_sent) : read_file(path, limit);
    VoxImportOptions vo;
    vo.chunk_edge = chunk_edge;
    vo.memory_limit_bytes = remaining_memory(limit, bytes.size());
    vo.keep_z = std::pair<std::int32_t, std::int32_t>{0, 0};
    const Box3i extent = vox_extent(parse_vox(bytes, path.string(), vo).info);
    if (extent.empty()) throw InvalidArgument(path.string() + ": the input holds no volume");
    const SlabPartition partition = checked_cut(cut, extent, size);
    const Box3i keep = kept_box(extent, partition, rank, ghost_slices);
    vo.keep_z = std::pair<std::int32_t, std::int32_t>{keep.begin.z, keep.end.z};
    const VoxImport slab = parse_vox(bytes, path.string(), vo);
    World part = rechunk_world(slab.world, chunk_edge, keep, path.string());
    part.palette = slab.world.palette;
    return WorldSlab{std::move(part), partition, "vox", true};
  });
}

}  // namespace

WorldSlab load_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                          int ghost_slices, const SlabReadOptions& read) {
  int size = 0;
  MPI_Comm_size(comm, &size);
  return load_world_slab(
      comm, path, chunk_edge, ghost_slices,
      [&](const Box3i& domain) { return partition_slabs(domain, size, chunk_edge); }, read);
}

WorldSlab load_world_slab(MPI_Comm comm, const std::filesystem::path& path, int chunk_edge,
                          int ghost_slices, const SlabCut& cut, const SlabReadOptions& read) {
  WorldSlab slab = read_world_slab(comm, path, chunk_edge, ghost_slices, cut, read);
  slab.read_by = read.read_by;
  return slab;
}

WorldSlab load_world_slab_by_content(MPI_Comm comm, const std::filesystem::path& path,
                                     int chunk_edge, int ghost_slices,
                                     const SlabReadOptions& read) {
  int size = 0;
  MPI_Comm_size(comm, &size);
  std::vector<double> weights;
  {
    const WorldSlab equal = load_world_slab(comm, path, chunk_edge, ghost_slices, read);
    weights = content_unit_weights(comm, equal.partition, equal.world, chunk_edge);
  }  // the first reading goes before the second
  return load_world_slab(
      comm, path, chunk_edge, ghost_slices,
      [&](const Box3i& domain) { return partition_slabs(domain, size, chunk_edge, weights); },
      read);
}

}  // namespace voxfield::mpi
