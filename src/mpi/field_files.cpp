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
#include "voxfield/npy.h"

namespace voxfield::mpi {
namespace {

// Writes `bytes` at `offset` of the open file, in pieces MPI's int counts can take.
void write_at(MPI_File fh, std::uint64_t offset, const std::uint8_t* bytes, std::uint64_t n,
              const std::string& name) {
  constexpr std::uint64_t kPiece = std::uint64_t{1} << 30;
  for (std::uint64_t at = 0; at < n; at += kPiece) {
    const int count = static_cast<int>(std::min(kPiece, n - at));
    MPI_Status status;
    const int rc = MPI_File_write_at(fh, static_cast<MPI_Offset>(offset + at), bytes + at, count,
                                     MPI_BYTE, &status);
    if (rc != MPI_SUCCESS)
      throw IoError(name + ": write of " + std::to_string(count) + " bytes at offset " +
                    std::to_string(offset + at) + " failed: " + detail::mpi_error_text(rc));
  }
}

// One output: its temporary, the size of its header, and this rank's pieces (offset from the
// end of the header, bytes).
struct Piece {
  std::uint64_t offset;
  std::vector<std::uint8_t> bytes;
};

// This rank's values over its slab, x fastest, at the slab's place in the whole array.
Piece values_piece(const DistanceField& f, const Box3i& slab, const Box3i& domain) {
  return std::visit(
      [&](const auto& g) {
        using T = typename std::decay_t<decltype(g)>::value_type;
        Piece p;
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
std::vector<Piece> sites_pieces(const Grid<SiteOffset>& g, const Box3i& slab, const Box3i& domain) {
  const std::size_t n = static_cast<std::size_t>(slab.volume());
  std::vector<SiteOffset> dense(n);
  g.copy_to_dense(slab, dense.data());
  const std::uint64_t plane = static_cast<std::uint64_t>(domain.volume()) * 2;
  const std::uint64_t at = static_cast<std::uint64_t>(slab.begin.z - domain.begin.z) *
                           static_cast<std::uint64_t>(domain.size().x) *
                           static_cast<std::uint64_t>(domain.size().y) * 2;
  std::vector<Piece> out(3);
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

void check_outputs(MPI_Comm comm, const FieldFiles& files) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  detail::collectively(comm, nullptr, [&] {
    if (rank != 0) return;
    for (const auto* p : {&files.values, &files.sites, &files.json})
      if (!p->empty()) check_output_path(*p);
  });
}

void write_field_npy(MPI_Comm comm, const SlabPartition& partition, const DistanceField& slab,
                     const FieldFiles& files, ExchangeStats* stats) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  const Box3i& domain = partition.domain;
  const bool sites = !files.sites.empty();
  // Rank 0 stages the temporaries (headers written); the others learn their names.
  std::optional<FileTransaction> transaction;
  std::vector<std::uint8_t> values_head, sites_head;
  std::string temporaries;  // values '\n' sites
  detail::collectively(comm, stats, [&] {
    if (!slab.domain.contains(partition.slab(rank)))
      throw InvalidArgument("this rank's field covers " + to_string(slab.domain) +
                            ", not all of its slab " + to_string(partition.slab(rank)));
    if (sites && !slab.sites) throw InvalidArgument("the field has no nearest sites to write");
    values_head = npy_header(values_dtype(slab), domain.size());
    if (sites) sites_head = npy_header(DType::kInt16, domain.size(), 3);
    if (rank != 0) return;
    transaction.emplace();
    temporaries = transaction->stage_shared(files.values, values_head).string();
    if (sites) temporaries += "\n" + transaction->stage_shared(files.sites, sites_head).string();
    if (!files.json.empty()) transaction->stage(files.json, files.json_text);
  });
  int length = static_cast<int>(temporaries.size());
  {
    detail::CollectiveTimer t(stats);
    MPI_Bcast(&length, 1, MPI_INT, 0, comm);
    temporaries.resize(static_cast<std::size_t>(length));
    MPI_Bcast(temporaries.data(), length, MPI_CHAR, 0, comm);
  }
  const std::size_t cut = temporaries.find('\n');
  const std::string values_tmp = temporaries.substr(0, cut);
  const std::string sites_tmp = cut == std::string::npos ? "" : temporaries.substr(cut + 1);

  // Each output: open collectively, write this rank's pieces, close collectively. The open and
  // close are collective calls every rank makes whatever happened before, so an error is
  // carried to the agreement below instead of leaving a rank behind.
  std::string error;
  auto write_output = [&](const std::string& tmp, const std::string& target,
                          std::uint64_t head_bytes, const std::vector<Piece>& pieces) {
    MPI_File fh = MPI_FILE_NULL;
    std::string mpi_path = tmp;
    const int rc = MPI_File_open(comm, mpi_path.data(), MPI_MODE_WRONLY, MPI_INFO_NULL, &fh);
    if (rc != MPI_SUCCESS) {
      if (error.empty())
        error = target + ": cannot open " + tmp + ": " + detail::mpi_error_text(rc);
      return;
    }
    try {
      for (const Piece& p : pieces)
        write_at(fh, head_bytes + p.offset, p.bytes.data(), p.bytes.size(), target);
    } catch (const std::exception& e) {
      if (error.empty()) error = e.what();
    }
    const int close_rc = MPI_File_close(&fh);
    if (close_rc != MPI_SUCCESS && error.empty())
      error = target + ": close failed: " + detail::mpi_error_text(close_rc);
  };
  {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<Piece> values;
    std::vector<Piece> site_planes;
    try {
      values.push_back(values_piece(slab, partition.slab(rank), domain));
      if (sites) site_planes = sites_pieces(*slab.sites, partition.slab(rank), domain);
    } catch (const std::exception& e) {
      error = e.what();
      values.clear();
      site_planes.clear();
    }
    write_output(values_tmp, files.values.string(), values_head.size(), values);
    if (sites) write_output(sites_tmp, files.sites.string(), sites_head.size(), site_planes);
    if (stats) stats->exchange_ms += detail::ms_since(t0);
  }
  detail::agree(comm, error, stats);
  // Every rank wrote its slices: rank 0 renames the temporaries onto the targets.
  detail::collectively(comm, stats, [&] {
    if (rank == 0) transaction->commit();
  });
}

}  // namespace voxfield::mpi
