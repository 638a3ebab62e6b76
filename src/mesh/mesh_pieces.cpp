// voxfield — a mesh built in pieces from some sample planes each, joined by the chunked mesher's
// weld (mesh_pieces.h). A piece is the chunked mesher's parts (chunked_mesh.h: per chunk, its
// vertices with their lattice element keys and ownership, and its triangles) for a run of chunk
// layers, in chunk order, behind a header naming the lattice, the options and the layers.
//
// Bytes, in the byte order of the machines (the ranks of one job share it; the header's marker
// refuses another): "VXMP", u32 version and byte-order marker, the lattice (3 × i32 samples,
// 3 × f64 origin, 3 × f64 spacing), the options (i32 chunk edge, i32 algorithm, f64 iso, u8 inside
// above, u8 analytic value, u8 analytic gradient), i32 first and end layer; then per chunk: u64
// vertices V, u64 indices I, u8 coloured, then V positions (3 × f32), V normals (3 × f32), V keys
// (u64), V sources (u64), V colours (3 × u8) when coloured, V owned and V shared flags (u8, 0 or
// 1), I indices (u32, each below V, I a multiple of 3).
#include "voxfield/mesh_pieces.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>

#include "chunked_mesh.h"
#include "mesh_internal.h"
#include "piece_parts.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {

namespace {

using detail::mesh::ChunkGrid;
using detail::mesh::ChunkPart;

constexpr char kMagic[4] = {'V', 'X', 'M', 'P'};
constexpr std::uint32_t kVersion = 1;
constexpr std::uint32_t kByteOrder = 0x01020304;
constexpr int kMaxSamples = 1 << 30;
// The fewest bytes a piece of `chunks` chunks takes: the header and each chunk's counts and flag.
constexpr std::uint64_t kHeaderBytes = 4 + 4 + 4 + 3 * 4 + 6 * 8 + 4 + 4 + 8 + 3 + 4 + 4;
constexpr std::uint64_t kChunkBytes = 8 + 8 + 1;

// What a piece says of its lattice and options: pieces join only when theirs are equal.
struct Header {
  Vec3i samples;
  std::array<double, 3> origin{}, spacing{};
  std::int32_t chunk_edge = 0, algorithm = 0;
  double iso = 0;
  std::uint8_t inside_above = 0, has_value = 0, has_gradient = 0;
  std::int32_t first_layer = 0, end_layer = 0;

  bool same_lattice(const Header& o) const {
    return samples == o.samples && origin == o.origin && spacing == o.spacing &&
           chunk_edge == o.chunk_edge && algorithm == o.algorithm && iso == o.iso &&
           inside_above == o.inside_above && has_value == o.has_value &&
           has_gradient == o.has_gradient;
  }
};

// Chunks in a piece's layers.
std::uint64_t chunks_of(const Header& h) {
  const ChunkGrid grid(h.samples, h.chunk_edge);
  return mul_sat(mul_sat(static_cast<std::uint64_t>(grid.count.x), grid.count.y),
                 static_cast<std::uint64_t>(h.end_layer - h.first_layer));
}

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  template <class T>
  void put_all(const std::vector<T>& v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(v.data());
    bytes.insert(bytes.end(), p, p + v.size() * sizeof(T));
  }
  std::vector<std::uint8_t> bytes;
};

// Reads a piece's bytes; every read checked against what is left (InvalidArgument naming the
// piece and what was cut short).
class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, std::size_t piece,
         const char* who = "join_mesh_pieces")
      : bytes_(bytes), piece_(piece), who_(who) {}
  [[noreturn]] void fail(const std::string& why) const {
    throw InvalidArgument(std::string(who_) + ": piece " + std::to_string(piece_) + " (byte " +
                          std::to_string(at_) + "): " + why);
  }
  template <class T>
  T get(const char* what) {
    if (bytes_.size() - at_ < sizeof(T)) fail(std::string("ends inside its ") + what);
    T v;
    std::memcpy(&v, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  template <class T>
  void get_all(std::vector<T>& out, std::uint64_t n, const char* what) {
    if (n > (bytes_.size() - at_) / sizeof(T))
      fail(std::string("ends inside its ") + what + " (" + std::to_string(n) + " declared)");
    out.resize(static_cast<std::size_t>(n));
    if (n == 0) return;  // an empty vector's data() may be null, which memcpy must not get
    std::memcpy(out.data(), bytes_.data() + at_, static_cast<std::size_t>(n) * sizeof(T));
    at_ += static_cast<std::size_t>(n) * sizeof(T);
  }
  bool done() const { return at_ == bytes_.size(); }
  std::uint64_t left() const { return bytes_.size() - at_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t piece_, at_ = 0;
  const char* who_;
};

void check_layers(Vec3i samples, int chunk_edge, int first_layer, int end_layer, const char* who) {
  const int layers = mesh_chunk_layers(samples, chunk_edge);
  if (!(first_layer >= 0 && first_layer < end_layer && end_layer <= layers))
    throw InvalidArgument(std::string(who) + ": chunk layers [" + std::to_string(first_layer) +
                          ", " + std::to_string(end_layer) + ") are not a run within the " +
                          std::to_string(layers) + " layers of the lattice");
}

Header read_header(Reader& r) {
  char magic[4];
  for (char& c : magic) c = r.get<char>("marker");
  if (std::memcmp(magic, kMagic, 4) != 0) r.fail("not a voxfield mesh piece (no VXMP marker)");
  if (const auto v = r.get<std::uint32_t>("version"); v != kVersion)
    r.fail("version " + std::to_string(v) + ", this voxfield joins version " +
           std::to_string(kVersion));
  if (r.get<std::uint32_t>("byte-order marker") != kByteOrder)
    r.fail("written on a machine of another byte order");
  Header h;
  for (int a = 0; a < 3; ++a) h.samples[a] = r.get<std::int32_t>("lattice size");
  for (double& o : h.origin) o = r.get<double>("origin");
  for (double& s : h.spacing) s = r.get<double>("spacing");
  h.chunk_edge = r.get<std::int32_t>("chunk edge");
  h.algorithm = r.get<std::int32_t>("algorithm");
  h.iso = r.get<double>("iso value");
  h.inside_above = r.get<std::uint8_t>("options");
  h.has_value = r.get<std::uint8_t>("options");
  h.has_gradient = r.get<std::uint8_t>("options");
  h.first_layer = r.get<std::int32_t>("layers");
  h.end_layer = r.get<std::int32_t>("layers");
  for (int a = 0; a < 3; ++a)
    if (h.samples[a] < 2 || h.samples[a] > kMaxSamples)
      r.fail("a lattice size outside 2..2^30 samples along an axis");
  if (h.chunk_edge < 2 || h.chunk_edge > 256) r.fail("a chunk edge outside 2..256");
  if (h.algorithm < 0 || h.algorithm > 2) r.fail("an unknown mesher");
  for (int a = 0; a < 3; ++a)
    if (!std::isfinite(h.origin[static_cast<std::size_t>(a)]) ||
        !std::isfinite(h.spacing[static_cast<std::size_t>(a)]))
      r.fail("an origin or spacing that is not finite");
  if (!std::isfinite(h.iso)) r.fail("an iso value that is not finite");
  try {
    check_layers(h.samples, h.chunk_edge, h.first_layer, h.end_layer, "layers");
  } catch (const InvalidArgument& e) {
    r.fail(e.what());
  }
  // Every chunk the header declares takes at least its counts: a header cannot promise more
  // chunks than its bytes hold (nor make the join allocate for them).
  if (mul_sat(chunks_of(h), kChunkBytes) > r.left())
    r.fail("declares " + std::to_string(chunks_of(h)) + " chunks, more than its bytes hold");
  return h;
}

void read_part(Reader& r, ChunkPart& p) {
  const auto vertices = r.get<std::uint64_t>("vertex count");
  const auto indices = r.get<std::uint64_t>("index count");
  const auto colored = r.get<std::uint8_t>("colour flag");
  if (colored > 1) r.fail("a colour flag that is neither 0 nor 1");
  if (indices % 3 != 0) r.fail("an index count that is not a multiple of 3");
  r.get_all(p.positions, vertices, "positions");
  r.get_all(p.normals, vertices, "normals");
  r.get_all(p.keys, vertices, "vertex keys");
  r.get_all(p.sources, vertices, "vertex sources");
  if (colored) r.get_all(p.colors, vertices, "colours");
  r.get_all(p.owned, vertices, "ownership flags");
  r.get_all(p.shared, vertices, "ownership flags");
  r.get_all(p.indices, indices, "indices");
  for (std::size_t i = 0; i < p.owned.size(); ++i)
    if (p.owned[i] > 1 || p.shared[i] > p.owned[i]) r.fail("an ownership flag out of range");
  for (const std::uint32_t i : p.indices)
    if (i >= vertices) r.fail("an index past the chunk's vertices");
}

}  // namespace

namespace detail::mesh {

PieceParts decode_piece(std::span<const std::uint8_t> piece, std::size_t index, const char* who) {
  require_memory(piece.size(), 0, who, "the piece's chunks");
  Reader r(piece, index, who);
  const Header h = read_header(r);
  PieceParts d;
  d.samples = h.samples;
  d.chunk_edge = h.chunk_edge;
  d.first_layer = h.first_layer;
  d.end_layer = h.end_layer;
  d.parts.resize(static_cast<std::size_t>(chunks_of(h)));
  for (ChunkPart& p : d.parts) read_part(r, p);
  if (!r.done()) r.fail("bytes past its last chunk");
  return d;
}

PieceParts mesh_piece_parts(const ScalarVolume& frame, int planes_z0, int plane_count,
                            const float* planes, const MeshOptions& options, int first_layer,
                            int end_layer) {
  const auto [need_begin, need_end] =
      mesh_layer_planes(frame.size, options.chunk_edge, first_layer, end_layer);
  if (!planes || planes_z0 > need_begin ||
      planes_z0 + static_cast<std::int64_t>(plane_count) < static_cast<std::int64_t>(need_end))
    throw InvalidArgument("mesh_piece: chunk layers [" + std::to_string(first_layer) + ", " +
                          std::to_string(end_layer) + ") read sample planes [" +
                          std::to_string(need_begin) + ", " + std::to_string(need_end) +
                          "), the piece holds [" + std::to_string(planes_z0) + ", " +
                          std::to_string(planes_z0 + static_cast<std::int64_t>(plane_count)) + ")");
  const std::size_t plane = static_cast<std::size_t>(frame.size.x) * frame.size.y;
  // The planes stand in for the whole lattice: a block's reads (always within the planes the
  // layers need, checked above) are copied out of them.
  const std::function<void(const Box3i&, float*)> fill = [&](const Box3i& region, float* out) {
    for (int z = region.begin.z; z < region.end.z; ++z)
      for (int y = region.begin.y; y < region.end.y; ++y) {
        const float* row = planes + plane * static_cast<std::size_t>(z - planes_z0) +
                           static_cast<std::size_t>(frame.size.x) * y + region.begin.x;
        out = std::copy(row, row + (region.end.x - region.begin.x), out);
      }
  };
  ScalarVolume whole = frame;
  whole.values = nullptr;
  const Lattice lattice = checked_lattice(whole, options, false, &fill);
  const ChunkGrid grid(frame.size, options.chunk_edge);
  const std::int64_t per_layer = static_cast<std::int64_t>(grid.count.x) * grid.count.y;
  const std::int64_t count = per_layer * (end_layer - first_layer);
  require_memory(mul_sat(static_cast<std::uint64_t>(count), 256), 0, "mesh",
                 "chunks of " + std::to_string(options.chunk_edge) + " cells (" +
                     std::to_string(count) + " in the piece; choose a larger --chunk)");
  std::vector<std::int64_t> chunks;
  chunks.reserve(static_cast<std::size_t>(count));
  for (std::int64_t c = first_layer * per_layer; c < end_layer * per_layer; ++c)
    chunks.push_back(c);
  PieceParts piece;
  piece.samples = frame.size;
  piece.chunk_edge = options.chunk_edge;
  piece.first_layer = first_layer;
  piece.end_layer = end_layer;
  piece.parts.resize(chunks.size());
  mesh_chunks(lattice, grid, options, chunks, piece.parts);
  return piece;
}

}  // namespace detail::mesh

int mesh_chunk_layers(Vec3i samples, int chunk_edge) {
  if (samples.x < 2 || samples.y < 2 || samples.z < 2)
    throw InvalidArgument("mesh: the lattice needs at least 2 samples along each axis");
  // voxfield's coordinate range (a chunk count per axis then fits an int with room to spare).
  if (samples.x > kMaxSamples || samples.y > kMaxSamples || samples.z > kMaxSamples)
    throw InvalidArgument("mesh: a lattice of more than 2^30 samples along an axis");
  if (chunk_edge < 2 || chunk_edge > 256)
    throw InvalidArgument("mesh: chunk edge " + std::to_string(chunk_edge) + " is outside 2..256");
  return ChunkGrid(samples, chunk_edge).count.z;
}

std::pair<int, int> mesh_layer_planes(Vec3i samples, int chunk_edge, int first_layer,
                                      int end_layer) {
  check_layers(samples, chunk_edge, first_layer, end_layer, "mesh_layer_planes");
  // Block::load's reads: three samples before a chunk's cells to two past its last corner.
  const int cells_begin = first_layer * chunk_edge;
  const int cells_end = std::min(end_layer * chunk_edge, samples.z - 1);
  return {std::max(cells_begin - 3, 0), std::min(cells_end + 3, samples.z)};
}

std::vector<std::uint8_t> mesh_piece(const ScalarVolume& frame, int planes_z0, int plane_count,
                                     const float* planes, const MeshOptions& options,
                                     int first_layer, int end_layer) {
  const std::vector<ChunkPart> parts =
      detail::mesh::mesh_piece_parts(frame, planes_z0, plane_count, planes, options, first_layer,
                                     end_layer)
          .parts;
  Writer w;
  // The exact size first: one allocation, no copies as the piece grows.
  std::size_t size = kHeaderBytes;
  for (const ChunkPart& p : parts)
    size += kChunkBytes + p.positions.size() * (12 + 12 + 8 + 8 + 1 + 1) + p.colors.size() * 3 +
            p.indices.size() * 4;
  w.bytes.reserve(size);
  for (const char c : kMagic) w.put(c);
  w.put(kVersion);
  w.put(kByteOrder);
  for (int a = 0; a < 3; ++a) w.put(static_cast<std::int32_t>(frame.size[a]));
  for (const double o : frame.origin_units) w.put(o);
  for (const double s : frame.spacing_units) w.put(s);
  w.put(static_cast<std::int32_t>(options.chunk_edge));
  w.put(static_cast<std::int32_t>(options.algorithm));
  w.put(options.iso);
  w.put(static_cast<std::uint8_t>(options.inside_above));
  w.put(static_cast<std::uint8_t>(static_cast<bool>(options.value)));
  w.put(static_cast<std::uint8_t>(static_cast<bool>(options.gradient)));
  w.put(static_cast<std::int32_t>(first_layer));
  w.put(static_cast<std::int32_t>(end_layer));
  for (const ChunkPart& p : parts) {
    w.put(static_cast<std::uint64_t>(p.positions.size()));
    w.put(static_cast<std::uint64_t>(p.indices.size()));
    w.put(static_cast<std::uint8_t>(!p.colors.empty()));
    w.put_all(p.positions);
    w.put_all(p.normals);
    w.put_all(p.keys);
    w.put_all(p.sources);
    w.put_all(p.colors);
    w.put_all(p.owned);
    w.put_all(p.shared);
    w.put_all(p.indices);
  }
  return std::move(w.bytes);
}

Mesh join_mesh_pieces(const std::vector<std::span<const std::uint8_t>>& pieces) {
  using namespace detail::mesh;
  if (pieces.empty()) throw InvalidArgument("join_mesh_pieces: no pieces");
  // The decoded parts take about the pieces' bytes again, beside the pieces themselves.
  std::uint64_t bytes = 0;
  for (const auto& p : pieces) bytes = add_sat(bytes, p.size());
  require_memory(add_sat(bytes, bytes), 0, "join_mesh_pieces", "the pieces and their chunks");
  std::vector<Header> headers;
  std::vector<Reader> readers;
  for (std::size_t i = 0; i < pieces.size(); ++i) {
    readers.emplace_back(pieces[i], i);
    headers.push_back(read_header(readers.back()));
    if (!headers.back().same_lattice(headers.front()))
      readers.back().fail("meshed from another lattice or with other options than piece 0");
  }
  const Header& h = headers.front();
  const ChunkGrid grid(h.samples, h.chunk_edge);
  // Every piece's chunks are backed by its bytes (read_header), so their sum is bounded by the
  // pieces' size; the whole grid's chunks must be too, or some layer is missing.
  const std::uint64_t per_layer_chunks =
      mul_sat(static_cast<std::uint64_t>(grid.count.x), static_cast<std::uint64_t>(grid.count.y));
  const std::uint64_t all_chunks =
      mul_sat(per_layer_chunks, static_cast<std::uint64_t>(grid.count.z));
  if (mul_sat(all_chunks, kChunkBytes) > bytes)
    throw InvalidArgument("join_mesh_pieces: the pieces hold fewer than the lattice's " +
                          std::to_string(all_chunks) + " chunks");
  require_memory(mul_sat(all_chunks, 256), 0, "join_mesh_pieces", "the lattice's chunks");
  const std::size_t per_layer = static_cast<std::size_t>(per_layer_chunks);
  // Which piece holds each layer: every layer once.
  std::vector<int> holder(static_cast<std::size_t>(grid.count.z), -1);
  for (std::size_t i = 0; i < headers.size(); ++i)
    for (int k = headers[i].first_layer; k < headers[i].end_layer; ++k) {
      if (holder[static_cast<std::size_t>(k)] >= 0)
        readers[i].fail("chunk layer " + std::to_string(k) + " is in piece " +
                        std::to_string(holder[static_cast<std::size_t>(k)]) + " too");
      holder[static_cast<std::size_t>(k)] = static_cast<int>(i);
    }
  for (std::size_t k = 0; k < holder.size(); ++k)
    if (holder[k] < 0)
      throw InvalidArgument("join_mesh_pieces: no piece holds chunk layer " + std::to_string(k) +
                            " of " + std::to_string(holder.size()));
  std::vector<ChunkPart> parts(per_layer * holder.size());
  for (std::size_t i = 0; i < headers.size(); ++i) {
    const std::size_t first = per_layer * static_cast<std::size_t>(headers[i].first_layer);
    const std::size_t end = per_layer * static_cast<std::size_t>(headers[i].end_layer);
    for (std::size_t c = first; c < end; ++c) read_part(readers[i], parts[c]);
    if (!readers[i].done()) readers[i].fail("bytes past its last chunk");
  }
  bool colored = false;
  for (const ChunkPart& p : parts) colored |= !p.colors.empty();
  if (colored)
    for (const ChunkPart& p : parts)
      if (p.colors.empty() && !p.positions.empty())
        throw InvalidArgument("join_mesh_pieces: some chunks have colours and some do not");
  return weld(parts, nullptr);
}

}  // namespace voxfield
