// voxfield — one .npy per output from every rank's slab of a field (mpi.h), all or nothing.
//
// The files are .npy arrays in Fortran order (x fastest), so a z-slab is one contiguous range of
// each: rank r writes its slices at header + z-offset with MPI-IO, into temporaries that rank 0
// staged beside the targets and renames onto them once every rank has written.
#include <chrono>
#include <cstring>
#include <optional>

#include "collective.h"
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

}  // namespace

void check_outputs(MPI_Comm comm, const std::vector<std::filesystem::path>& shared,
                   const std::vector<std::filesystem::path>& rank0) {
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
  });
}

void write_field_npy(MPI_Comm comm, const SlabPartition& partition, const DistanceField& slab,
                     const FieldFiles& files, ExchangeStats* stats, FileTransaction* into) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const Box3i& domain = partition.domain;
  const bool sites = !files.sites.empty();
  // Rank 0 stages the temporaries (headers written); the others learn their names.
  std::optional<FileTransaction> own;
  FileTransaction* transaction = into;
  std::vector<std::uint8_t> values_head, sites_head;
  std::string temporaries;  // values '\n' sites
  detail::collectively(comm, stats, [&] {
    detail::require_partition(comm, partition);
    if (!slab.domain.contains(partition.slab(rank)))
      throw InvalidArgument("this rank's field covers " + to_string(slab.domain) +
                            ", not all of its slab " + to_string(partition.slab(rank)));
    if (sites && !slab.sites) throw InvalidArgument("the field has no nearest sites to write");
    values_head = npy_header(values_dtype(slab), domain.size());
    if (sites) sites_head = npy_header(DType::kInt16, domain.size(), 3);
    if (rank != 0) return;
    if (!transaction) transaction = &own.emplace();
    temporaries = transaction->stage_shared(files.values, values_head).string();
    // '\0' between the names: the one byte no path holds.
    if (sites)
      temporaries +=
          std::string(1, '\0') + transaction->stage_shared(files.sites, sites_head).string();
    if (!files.json.empty()) transaction->stage(files.json, files.json_text);
  });
  temporaries = detail::broadcast_string(comm, temporaries, stats);
  const std::size_t cut = temporaries.find('\0');
  const std::string values_tmp = temporaries.substr(0, cut);
  const std::string sites_tmp = cut == std::string::npos ? "" : temporaries.substr(cut + 1);

  std::string error;
  {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<detail::FilePiece> values;
    std::vector<detail::FilePiece> site_planes;
    try {
      values.push_back(values_piece(slab, partition.slab(rank), domain));
      if (sites) site_planes = sites_pieces(*slab.sites, partition.slab(rank), domain);
    } catch (const std::exception& e) {
      error = e.what();
      values.clear();
      site_planes.clear();
    }
    // The pieces' offsets count from the end of the headers.
    for (auto& p : values) p.offset += values_head.size();
    for (auto& p : site_planes) p.offset += sites_head.size();
    const std::string e1 = detail::write_pieces(comm, values_tmp, files.values.string(), values);
    if (error.empty()) error = e1;
    if (sites) {
      const std::string e2 =
          detail::write_pieces(comm, sites_tmp, files.sites.string(), site_planes);
      if (error.empty()) error = e2;
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
