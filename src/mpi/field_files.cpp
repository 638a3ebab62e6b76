// voxfield — one .npy per output from every rank's slab of a field (mpi.h), all or nothing.
//
// The files are .npy arrays in Fortran order (x fastest), so a z-slab is one contiguous range of
// each: rank r writes its slices at header + z-offset with MPI-IO, into temporaries that rank 0
// staged beside the targets and renames onto them once every rank has written.
#include <chrono>
#include <cstring>
#include <optional>

#include "collective.h"
#include "voxfield/dissertation_format.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/npy.h"

namespace voxfield::mpi {
namespace {

// This rank's values over its slab, x fastest, at the slab's place in the whole array.
detail::FilePiece values_piece(const DistanceField& f, const Box3i& slab, const Box3i& domain) {
  return std::visit(
      [&](const auto& g) {
        using T = typename std::decay_t<decltype(g)>::value_type;
        require_memory(dense_bytes(slab, sizeof(T)), 0, "field output",
                       "a dense copy of this rank's slab " + to_string(slab));
        detail::FilePiece p;
        p.offset = static_cast<std::uint64_t>(slab.begin.z - domain.begin.z) *
                   static_cast<std::uint64_t>(domain.size().x) *
                   static_cast<std::uint64_t>(domain.size().y) * sizeof(T);
        p.bytes.resize(static_cast<std::size_t>(slab.volume()) * sizeof(T));
        g.copy_to_dense(slab, reinterpret_cast<T*>(p.bytes.data()));
        return p;
      },
      f.values);
}

DType values_dtype(const DistanceField& f) {
  switch (f.options.storage) {
    case Storage::kU8:
      return DType::kUInt8;
    case Storage::kU16:
      return DType::kUInt16;
    case Storage::kF32:
      return DType::kFloat32;
  }
  return DType::kFloat32;
}

// The nearest-site offsets as three int16 planes (dx, dy, dz), each at its place in its plane of
// the whole a[x, y, z, 3] array (component slowest), -32768 where there is none.
std::vector<detail::FilePiece> sites_pieces(const Grid<SiteOffset>& g, const Box3i& slab,
                                            const Box3i& domain) {
  // The offsets and their three planes are alive at once.
  require_memory(dense_bytes(slab, 2 * sizeof(SiteOffset)), 0, "--sites output",
                 "a dense copy of this rank's slab " + to_string(slab));
  const std::size_t n = static_cast<std::size_t>(slab.volume());
  std::vector<SiteOffset> dense(n);
  g.copy_to_dense(slab, dense.data());
  const std::uint64_t plane = static_cast<std::uint64_t>(domain.volume()) * 2;
  const std::uint64_t at = static_cast<std::uint64_t>(slab.begin.z - domain.begin.z) *
                           static_cast<std::uint64_t>(domain.size().x) *
                           static_cast<std::uint64_t>(domain.size().y) * 2;
  std::vector<detail::FilePiece> out(3);
  for (int c = 0; c < 3; ++c) {
    out[static_cast<std::size_t>(c)].offset = static_cast<std::uint64_t>(c) * plane + at;
    std::vector<std::uint8_t>& b = out[static_cast<std::size_t>(c)].bytes;
    b.resize(n * 2);
    for (std::size_t i = 0; i < n; ++i) {
      const std::int16_t v = c == 0 ? dense[i].dx : c == 1 ? dense[i].dy : dense[i].dz;
      std::memcpy(b.data() + 2 * i, &v, 2);
    }
  }
  return out;
}

// The dissertation's packed voxels of this rank's slab (dissertation_format.h), at its place.
detail::FilePiece packed_piece(const World& world, const DistanceField& f, const Box3i& slab,
                               const Box3i& domain) {
  // At its peak, packing holds 13 bytes a voxel: the words, a byte of material and a float.
  require_memory(dense_bytes(slab, 13), 0, "--packed output",
                 "a dense copy of this rank's slab " + to_string(slab));
  const std::vector<std::uint32_t> packed = pack_dissertation_format(world, f, slab);
  detail::FilePiece p;
  p.offset = static_cast<std::uint64_t>(slab.begin.z - domain.begin.z) *
             static_cast<std::uint64_t>(domain.size().x) *
             static_cast<std::uint64_t>(domain.size().y) * sizeof(std::uint32_t);
  p.bytes.resize(packed.size() * sizeof(std::uint32_t));
  std::memcpy(p.bytes.data(), packed.data(), p.bytes.size());
  return p;
}

// The world's materials over this rank's slab, at its place.
detail::FilePiece materials_piece(const World& world, const Box3i& slab, const Box3i& domain) {
  require_memory(dense_bytes(slab, 1), 0, "materials output",
                 "a dense copy of this rank's slab " + to_string(slab));
  detail::FilePiece p;
  p.offset = static_cast<std::uint64_t>(slab.begin.z - domain.begin.z) *
             static_cast<std::uint64_t>(domain.size().x) *
             static_cast<std::uint64_t>(domain.size().y);
  p.bytes.resize(static_cast<std::size_t>(slab.volume()));
  world.voxels.copy_to_dense(slab, p.bytes.data());
  return p;
}

}  // namespace

void check_outputs(MPI_Comm comm, const std::vector<std::filesystem::path>& shared,
                   const std::vector<std::filesystem::path>& rank0,
                   const std::vector<std::filesystem::path>& inputs) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  detail::collectively(comm, nullptr, [&] {
    if (rank != 0) return;
    for (const auto& p : shared) {
      if (p.empty()) continue;
      check_output_path(p);
      // Every rank writes into these: standard output, a device or a FIFO cannot take that.
      std::error_code ec;
      const auto st = std::filesystem::status(p, ec);
      if (p == "-" || (!ec && std::filesystem::exists(st) && !std::filesystem::is_regular_file(st)))
        throw IoError(p.string() + ": is not a regular file, which the ranks could write together");
    }
    for (const auto& p : rank0)
      if (!p.empty()) check_output_path(p);
    std::vector<std::filesystem::path> targets;
    for (const auto* list : {&shared, &rank0})
      for (const auto& p : *list) {
        if (p.empty()) continue;
        for (const auto& in : inputs)
          if (same_target(p, in))
            throw InvalidArgument(p.string() +
                                  " is also an input of this command; writing it would destroy " +
                                  in.string() + " (choose another output)");
        for (const auto& t : targets)
          if (same_target(p, t)) throw InvalidArgument(p.string() + " is given as two outputs");
        targets.push_back(p);
      }
  });
}

void write_field_npy(MPI_Comm comm, const SlabPartition& partition, const DistanceField& slab,
                     const FieldFiles& files, ExchangeStats* stats, FileTransaction* into) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const Box3i& domain = partition.domain;
  // The outputs in order: the values, then the sites, the packed voxels and the materials when
  // asked for.
  struct Output {
    const std::filesystem::path* path;
    std::vector<std::uint8_t> head;
    std::string temporary;
    std::vector<detail::FilePiece> pieces;
  };
  std::vector<Output> outputs;
  // Rank 0 stages the temporaries (headers written); the others learn their names.
  std::optional<FileTransaction> own;
  FileTransaction* transaction = into;
  std::string temporaries;  // '\0' between the names: the one byte no path holds
  detail::collectively(comm, stats, [&] {
    detail::require_partition(comm, partition);
    if (!slab.domain.contains(partition.slab(rank)))
      throw InvalidArgument("this rank's field covers " + to_string(slab.domain) +
                            ", not all of its slab " + to_string(partition.slab(rank)));
    if (!files.sites.empty() && !slab.sites)
      throw InvalidArgument("the field has no nearest sites to write");
    if ((!files.packed.empty() || !files.materials.empty()) && !files.world)
      throw InvalidArgument(
          "packed voxels and materials need this rank's world (FieldFiles::world)");
    if (!files.values.empty())
      outputs.push_back({&files.values, npy_header(values_dtype(slab), domain.size()), {}, {}});
    if (!files.sites.empty())
      outputs.push_back({&files.sites, npy_header(DType::kInt16, domain.size(), 3), {}, {}});
    if (!files.packed.empty())
      outputs.push_back({&files.packed, npy_header(DType::kUInt32, domain.size()), {}, {}});
    if (!files.materials.empty())
      outputs.push_back({&files.materials, npy_header(DType::kUInt8, domain.size()), {}, {}});
    if (rank != 0) return;
    if (!transaction) transaction = &own.emplace();
    for (std::size_t k = 0; k < outputs.size(); ++k)
      temporaries += (k ? std::string(1, '\0') : std::string()) +
                     transaction->stage_shared(*outputs[k].path, outputs[k].head).string();
    if (!files.json.empty()) transaction->stage(files.json, files.json_text);
  });
  temporaries = detail::broadcast_string(comm, temporaries, stats);
  for (std::size_t k = 0, at = 0; k < outputs.size(); ++k) {
    const std::size_t cut = temporaries.find('\0', at);
    outputs[k].temporary = temporaries.substr(at, cut == std::string::npos ? cut : cut - at);
    at = cut + 1;
  }

  std::string error;
  {
    const auto t0 = std::chrono::steady_clock::now();
    const Box3i mine = partition.slab(rank);
    try {
      std::size_t k = 0;
      if (!files.values.empty()) outputs[k++].pieces.push_back(values_piece(slab, mine, domain));
      if (!files.sites.empty()) outputs[k++].pieces = sites_pieces(*slab.sites, mine, domain);
      if (!files.packed.empty())
        outputs[k++].pieces.push_back(packed_piece(*files.world, slab, mine, domain));
      if (!files.materials.empty())
        outputs[k++].pieces.push_back(materials_piece(*files.world, mine, domain));
    } catch (const std::exception& e) {
      error = e.what();
      for (Output& o : outputs) o.pieces.clear();
    }
    // Every rank writes into every temporary (nothing when it failed), so none waits on another.
    for (Output& o : outputs) {
      for (auto& p : o.pieces) p.offset += o.head.size();  // offsets count from the header's end
      const std::string e = detail::write_pieces(comm, o.temporary, o.path->string(), o.pieces);
      if (error.empty()) error = e;
    }
    if (stats) stats->exchange_ms += detail::ms_since(t0);
  }
  detail::agree(comm, error, stats);
  // Every rank wrote its slices: rank 0 renames the temporaries onto the targets (or its caller
  // does, with its other outputs).
  detail::collectively(comm, stats, [&] {
    if (rank == 0 && own) own->commit();
  });
}

}  // namespace voxfield::mpi
