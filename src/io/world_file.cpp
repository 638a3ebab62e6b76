// voxfield — .vfw world files (format: docs/formats.md, "voxfield world files").
//
// Layout, all little-endian:
//   header   "VXFWORLD" u32 version u32 section_count u32 crc32(previous 16 bytes)
//   sections u32 kind (1 world, 3 frame, 2 distance field), u64 bytes, payload, u32 crc32(payload)
// The frame section (format version 2) follows the world's when its frame is not the identity:
// 3 x f64 origin, 3 x f64 voxel size, 9 x f64 rotation (rows). A world in the identity frame is
// written as version 1, byte for byte what voxfield wrote before frames, so older readers read it.
// A grid inside a payload: u32 chunk_edge, u32 value_bytes, background value, u8 bounded
// [+ 6 x i32 bounds], u64 chunk_count, then per chunk: 3 x i32 coordinate, u8 kind (0 uniform: one
// value follows; 1 dense: u32 size + zlib stream of edge^3 values, x fastest).
// Every section carries its own CRC-32, so a flipped bit anywhere is caught before it is used.
#include "voxfield/world_file.h"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <type_traits>
#include <unordered_set>

#include "byte_reader.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"

namespace voxfield {
namespace {

constexpr char kMagic[8] = {'V', 'X', 'F', 'W', 'O', 'R', 'L', 'D'};
enum SectionKind : std::uint32_t { kWorldSection = 1, kFieldSection = 2, kFrameSection = 3 };

class Out {
 public:
  std::vector<std::uint8_t> b;
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    b.insert(b.end(), p, p + sizeof(T));
  }
  void bytes(const void* p, std::size_t n) {
    const auto* q = static_cast<const std::uint8_t*>(p);
    b.insert(b.end(), q, q + n);
  }
};

std::uint32_t crc(const std::uint8_t* p, std::size_t n) {
  uLong c = crc32(0L, Z_NULL, 0);
  while (n > 0) {
    const uInt part = static_cast<uInt>(std::min<std::size_t>(n, 1u << 30));
    c = crc32(c, p, part);
    p += part;
    n -= part;
  }
  return static_cast<std::uint32_t>(c);
}

// A grid's parameters and chunk count: what precedes its chunk records.
template <class T>
void put_grid_head(Out& o, int chunk_edge, T background, const std::optional<Box3i>& bounds,
                   std::uint64_t chunks) {
  o.put<std::uint32_t>(static_cast<std::uint32_t>(chunk_edge));
  o.put<std::uint32_t>(sizeof(T));
  o.put(background);
  o.put<std::uint8_t>(bounds ? 1 : 0);
  if (bounds) {
    for (int k = 0; k < 3; ++k) o.put<std::int32_t>(bounds->begin[k]);
    for (int k = 0; k < 3; ++k) o.put<std::int32_t>(bounds->end[k]);
  }
  o.put<std::uint64_t>(chunks);
}

// The records of the given chunks, in that order.
template <class T>
void put_chunk_records(Out& o, const Grid<T>& g, const std::vector<Vec3i>& coords) {
  const std::size_t raw = static_cast<std::size_t>(g.chunk_volume()) * sizeof(T);
  std::vector<std::uint8_t> packed(compressBound(static_cast<uLong>(raw)));
  for (const Vec3i c : coords) {
    o.put<std::int32_t>(c.x);
    o.put<std::int32_t>(c.y);
    o.put<std::int32_t>(c.z);
    const ChunkView<T> v = g.chunk_view(c);
    if (v.uniform()) {
      o.put<std::uint8_t>(0);
      o.put(v.uniform_value);
      continue;
    }
    o.put<std::uint8_t>(1);
    uLongf size = static_cast<uLongf>(packed.size());
    if (compress2(packed.data(), &size, reinterpret_cast<const Bytef*>(v.voxels),
                  static_cast<uLong>(raw), 1) != Z_OK) {
      throw Error("world file: zlib could not compress a chunk");
    }
    o.put<std::uint32_t>(static_cast<std::uint32_t>(size));
    o.bytes(packed.data(), size);
  }
}

template <class T>
void put_grid(Out& o, const Grid<T>& g) {
  const std::vector<Vec3i> coords = g.chunk_coords();
  put_grid_head(o, g.chunk_edge(), g.background(), g.bounds(), coords.size());
  put_chunk_records(o, g, coords);
}

template <class T>
T get(detail::ByteReader& r, const char* what) {
  T v;
  std::memcpy(&v, r.take(sizeof(T), what).data(), sizeof(T));
  return v;
}

// What a file will cost once decoded, counted before it is allocated.
class Budget {
 public:
  Budget(const std::string& name, std::uint64_t limit)
      : name_(name), limit_(effective_memory_limit(limit)) {}
  void charge(std::uint64_t bytes, const std::string& what) {
    used_ = add_sat(used_, bytes);
    require_memory(used_, limit_, name_, what);
  }

 private:
  const std::string& name_;
  std::uint64_t limit_;
  std::uint64_t used_ = 0;
};

constexpr std::uint64_t kBytesPerChunkNode = 96;  // hash node and bookkeeping of a stored chunk

// Which chunks a reader decodes: all, or those reaching into z in [z_begin, z_end) (a slab).
struct ChunkFilter {
  bool all = true;
  std::int32_t z_begin = 0, z_end = 0;
  template <class T>
  bool keeps(const Grid<T>& g, Vec3i chunk) const {
    if (all) return true;
    const Box3i b = g.chunk_box(chunk);
    return z_begin < z_end && b.begin.z < z_end && z_begin < b.end.z;
  }
};

// `stored` (when not null) gets the union of the boxes of the chunks stored with anything but
// the background (WorldFile::stored_chunks_box), kept by the filter or not.
template <class T>
Grid<T> get_grid(detail::ByteReader& r, Budget& budget, const ChunkFilter& filter = {},
                 Box3i* stored = nullptr) {
  const auto edge = get<std::uint32_t>(r, "chunk edge");
  if (edge < 8 || edge > 128 || (edge & (edge - 1)) != 0)
    r.fail("chunk edge " + std::to_string(edge) + " is not a power of two in 8..128");
  if (get<std::uint32_t>(r, "value size") != sizeof(T))
    r.fail("value size does not match the grid's type");
  const T background = get<T>(r, "background");
  std::optional<Box3i> bounds;
  if (get<std::uint8_t>(r, "bounds flag")) {
    const std::uint64_t at = r.offset();
    Box3i b;
    for (int k = 0; k < 3; ++k) b.begin[k] = get<std::int32_t>(r, "bounds");
    for (int k = 0; k < 3; ++k) b.end[k] = get<std::int32_t>(r, "bounds");
    if (b.empty()) r.fail_at(at, "empty grid bounds " + to_string(b));
    if (!kCoordRange.contains(b)) {
      r.fail_at(at, "grid bounds " + to_string(b) +
                        " reach outside the supported coordinate range " + to_string(kCoordRange));
    }
    bounds = b;
  }
  Grid<T> g(static_cast<int>(edge), background, bounds);
  const auto count = get<std::uint64_t>(r, "chunk count");
  if (count > r.remaining() / 13)
    r.fail("chunk count " + std::to_string(count) + " overruns the section");
  const std::size_t raw = static_cast<std::size_t>(g.chunk_volume()) * sizeof(T);

  // First pass over the chunk records (headers only): coordinates checked, duplicates refused and
  // the decoded size counted before any chunk is decompressed.
  {
    detail::ByteReader scan = r;
    std::unordered_set<Vec3i, Vec3iHash> seen;
    std::uint64_t dense = 0, kept = 0;
    for (std::uint64_t i = 0; i < count; ++i) {
      const std::uint64_t at = scan.offset();
      Vec3i c;
      c.x = get<std::int32_t>(scan, "chunk coordinate");
      c.y = get<std::int32_t>(scan, "chunk coordinate");
      c.z = get<std::int32_t>(scan, "chunk coordinate");
      const auto kind = get<std::uint8_t>(scan, "chunk kind");
      if (!g.chunk_in_range(c)) {
        scan.fail_at(at, "chunk " + to_string(c) + " of edge " + std::to_string(edge) +
                             " lies outside the supported coordinate range " +
                             to_string(kCoordRange));
      }
      if (bounds && g.chunk_box(c).intersect(*bounds).empty())
        scan.fail_at(at, "chunk " + to_string(c) + " lies outside the grid bounds");
      if (!seen.insert(c).second) scan.fail_at(at, "chunk " + to_string(c) + " appears twice");
      const bool keep = filter.keeps(g, c);  // only what is decoded is charged
      kept += keep;
      const Box3i box = bounds ? g.chunk_box(c).intersect(*bounds) : g.chunk_box(c);
      if (kind == 0) {
        // A uniform chunk the bounds cut through is stored densely (the part outside holds the
        // background), unless it holds the background itself.
        const T v = get<T>(scan, "uniform value");
        if (keep && bounds && !bounds->contains(g.chunk_box(c)) && !(v == background)) ++dense;
        if (stored && !(v == background)) *stored = stored->unite(box);
      } else if (kind == 1) {
        scan.skip(get<std::uint32_t>(scan, "chunk size"), "chunk data");
        dense += keep;
        if (stored) *stored = stored->unite(box);
      } else {
        scan.fail_at(at + 12, "unknown chunk kind " + std::to_string(kind));
      }
    }
    budget.charge(add_sat(mul_sat(dense, raw), mul_sat(kept, kBytesPerChunkNode)),
                  "a grid of " + std::to_string(kept) + " chunks (" + std::to_string(dense) +
                      " dense, " + std::to_string(raw) + " bytes each)");
  }

  std::vector<Vec3i> coords;
  std::vector<ChunkArray<T>> data;
  for (std::uint64_t i = 0; i < count; ++i) {
    Vec3i c;
    c.x = get<std::int32_t>(r, "chunk coordinate");
    c.y = get<std::int32_t>(r, "chunk coordinate");
    c.z = get<std::int32_t>(r, "chunk coordinate");
    const auto kind = get<std::uint8_t>(r, "chunk kind");
    if (!filter.keeps(g, c)) {  // checked by the first pass; its bytes are never decompressed
      if (kind == 0)
        r.skip(sizeof(T), "uniform value");
      else
        r.skip(get<std::uint32_t>(r, "chunk size"), "chunk data");
      continue;
    }
    if (kind == 0) {
      // Uniform chunks stay single values: no voxel array is allocated for them.
      const T v = get<T>(r, "uniform value");
      g.fill(bounds ? g.chunk_box(c).intersect(*bounds) : g.chunk_box(c), v);
      continue;
    }
    ChunkArray<T> voxels = make_chunk_array<T>(static_cast<std::size_t>(g.chunk_volume()));
    const auto size = get<std::uint32_t>(r, "chunk size");
    auto packed = r.take(size, "chunk data");
    uLongf out = static_cast<uLongf>(raw);
    if (uncompress(reinterpret_cast<Bytef*>(voxels.get()), &out, packed.data(), size) != Z_OK ||
        out != raw) {
      r.fail("chunk " + to_string(c) + " does not decompress to " + std::to_string(raw) + " bytes");
    }
    coords.push_back(c);
    data.push_back(std::move(voxels));
  }
  g.adopt_chunks(coords, std::move(data));
  return g;
}

void put_field(Out& o, const DistanceField& f) {
  const DistanceOptions& op = f.options;
  o.put<std::uint8_t>(static_cast<std::uint8_t>(op.metric));
  o.put<std::uint8_t>(op.signed_distance);
  o.put<std::uint8_t>(static_cast<std::uint8_t>(op.storage));
  o.put<std::uint8_t>(f.sites.has_value());
  o.put<double>(op.max_distance);
  for (double s : op.spacing) o.put<double>(s);
  o.put<double>(op.fixed_point_scale);
  for (int k = 0; k < 3; ++k) o.put<std::int32_t>(f.domain.begin[k]);
  for (int k = 0; k < 3; ++k) o.put<std::int32_t>(f.domain.end[k]);
  o.put<double>(f.encoding.scale);
  o.put<std::int64_t>(f.encoding.bias);
  std::visit([&](const auto& g) { put_grid(o, g); }, f.values);
  if (f.sites) put_grid(o, *f.sites);
}

bool finite_positive(double v) {
  return std::isfinite(v) && v > 0;
}

DistanceField get_field(detail::ByteReader& r, Budget& budget) {
  const std::uint64_t at = r.offset();
  DistanceField f;
  const auto metric = get<std::uint8_t>(r, "metric");
  const auto is_signed = get<std::uint8_t>(r, "signed");
  const auto storage = get<std::uint8_t>(r, "storage");
  const auto has_sites = get<std::uint8_t>(r, "sites flag");
  if (metric > 2 || storage > 2 || is_signed > 1 || has_sites > 1)
    r.fail("invalid distance field options");
  f.options.metric = static_cast<Metric>(metric);
  f.options.signed_distance = is_signed;
  f.options.storage = static_cast<Storage>(storage);
  f.options.nearest_sites = has_sites;
  f.options.max_distance = get<double>(r, "max distance");
  for (double& s : f.options.spacing) s = get<double>(r, "spacing");
  f.options.fixed_point_scale = get<double>(r, "fixed-point scale");
  for (int k = 0; k < 3; ++k) f.domain.begin[k] = get<std::int32_t>(r, "domain");
  for (int k = 0; k < 3; ++k) f.domain.end[k] = get<std::int32_t>(r, "domain");
  f.options.domain = f.domain;
  f.encoding.scale = get<double>(r, "scale");
  f.encoding.bias = get<std::int64_t>(r, "bias");
  // The options as compute_distance_field would accept them: a file is not a way around them.
  if (!std::isfinite(f.options.max_distance) || f.options.max_distance < 0) {
    r.fail_at(at + 4,
              "invalid clamp " + std::to_string(f.options.max_distance) + " (a finite value >= 0)");
  }
  for (double sp : f.options.spacing)
    if (!finite_positive(sp))
      r.fail_at(at + 12, "invalid voxel spacing " + std::to_string(sp) + " (finite, > 0)");
  if (!std::isfinite(f.options.fixed_point_scale) || f.options.fixed_point_scale < 0) {
    r.fail_at(at + 36, "invalid fixed-point scale " + std::to_string(f.options.fixed_point_scale));
  }
  for (int k = 0; k < 3; ++k) {
    if (f.domain.end[k] < f.domain.begin[k])
      r.fail_at(at + 44, "inverted field domain " + to_string(f.domain));
  }
  if (!f.domain.in_range()) {
    r.fail_at(at + 44, "field domain " + to_string(f.domain) +
                           " reaches outside the supported coordinate range");
  }
  if (!finite_positive(f.encoding.scale) || f.encoding.bias < 0 || f.encoding.bias > 65535) {
    r.fail_at(at + 68, "invalid field encoding");
  }
  switch (f.options.storage) {
    case Storage::kU8:
      f.values = get_grid<std::uint8_t>(r, budget);
      break;
    case Storage::kU16:
      f.values = get_grid<std::uint16_t>(r, budget);
      break;
    case Storage::kF32:
      f.values = get_grid<float>(r, budget);
      break;
  }
  if (has_sites) f.sites = get_grid<SiteOffset>(r, budget);
  return f;
}

void put_section(Out& file, std::uint32_t kind, const Out& payload) {
  file.put<std::uint32_t>(kind);
  file.put<std::uint64_t>(payload.b.size());
  file.bytes(payload.b.data(), payload.b.size());
  file.put<std::uint32_t>(crc(payload.b.data(), payload.b.size()));
}

// The header: version 2 when a frame section follows the world, 1 (the format before frames)
// otherwise.
void put_header(Out& file, const VoxelFrame& frame, std::uint32_t sections) {
  file.bytes(kMagic, 8);
  file.put<std::uint32_t>(frame.is_identity() ? 1 : kWorldFileVersion);
  file.put<std::uint32_t>(sections);
  file.put<std::uint32_t>(crc(file.b.data(), 16));
}

void put_frame_section(Out& file, const VoxelFrame& frame) {
  if (frame.is_identity()) return;
  frame.validate("world file: the world's frame");
  Out p;
  for (int a = 0; a < 3; ++a) p.put<double>(frame.origin_world[a]);
  for (int a = 0; a < 3; ++a) p.put<double>(frame.voxel_size_world[a]);
  for (const Vec3d& row : frame.rotation)
    for (int a = 0; a < 3; ++a) p.put<double>(row[a]);
  put_section(file, kFrameSection, p);
}

VoxelFrame get_frame(detail::ByteReader& r, std::uint64_t at) {
  VoxelFrame f;
  for (int a = 0; a < 3; ++a) f.origin_world[a] = get<double>(r, "frame origin");
  for (int a = 0; a < 3; ++a) f.voxel_size_world[a] = get<double>(r, "frame voxel size");
  for (Vec3d& row : f.rotation)
    for (int a = 0; a < 3; ++a) row[a] = get<double>(r, "frame rotation");
  try {
    f.validate("the world's frame");
  } catch (const InvalidArgument& e) {
    r.fail_at(at, e.what());
  }
  return f;
}

}  // namespace

std::vector<std::uint8_t> encode_world_file(const World& world,
                                            const std::vector<const DistanceField*>& fields) {
  Out file;
  put_header(file, world.frame,
             static_cast<std::uint32_t>(1 + !world.frame.is_identity() + fields.size()));
  Out w;
  for (const Rgba& c : world.palette) w.put(c);
  put_grid(w, world.voxels);
  put_section(file, kWorldSection, w);
  put_frame_section(file, world.frame);
  for (const DistanceField* f : fields) {
    Out p;
    put_field(p, *f);
    put_section(file, kFieldSection, p);
  }
  return std::move(file.b);
}

WorldFilePart encode_world_file_part(const Grid<std::uint8_t>& voxels, std::int32_t chunk_z_begin,
                                     std::int32_t chunk_z_end) {
  std::vector<Vec3i> coords = voxels.chunk_coords();
  std::erase_if(coords, [&](const Vec3i& c) { return c.z < chunk_z_begin || c.z >= chunk_z_end; });
  Out o;
  put_chunk_records(o, voxels, coords);
  WorldFilePart part;
  part.chunks = coords.size();
  part.crc = crc(o.b.data(), o.b.size());
  part.records = std::move(o.b);
  return part;
}

WorldFileFrame encode_world_file_frame(const Palette& palette, int chunk_edge,
                                       const std::optional<Box3i>& bounds,
                                       std::span<const WorldFilePartSummary> parts,
                                       const VoxelFrame& voxel_frame) {
  if (chunk_edge < 8 || chunk_edge > 128 || (chunk_edge & (chunk_edge - 1)) != 0)
    throw InvalidArgument("world file: chunk edge " + std::to_string(chunk_edge) +
                          " is not a power of two in 8..128");
  std::uint64_t chunks = 0, record_bytes = 0;
  for (const WorldFilePartSummary& p : parts) {
    chunks += p.chunks;
    record_bytes += p.bytes;
  }
  // The world section's payload starts with the palette and the grid's head; its CRC continues
  // over every part's records in order (zlib's crc32_combine joins CRCs of adjacent pieces).
  Out payload;
  for (const Rgba& c : palette) payload.put(c);
  put_grid_head<std::uint8_t>(payload, chunk_edge, 0, bounds, chunks);
  uLong section_crc = crc(payload.b.data(), payload.b.size());
  for (const WorldFilePartSummary& p : parts)
    section_crc = crc32_combine(section_crc, p.crc, static_cast<z_off_t>(p.bytes));
  WorldFileFrame frame;
  Out head;
  put_header(head, voxel_frame, voxel_frame.is_identity() ? 1 : 2);
  head.put<std::uint32_t>(kWorldSection);
  head.put<std::uint64_t>(payload.b.size() + record_bytes);
  head.bytes(payload.b.data(), payload.b.size());
  frame.head = std::move(head.b);
  Out tail;
  tail.put<std::uint32_t>(static_cast<std::uint32_t>(section_crc));
  put_frame_section(tail, voxel_frame);
  frame.tail = std::move(tail.b);
  return frame;
}

WorldFile parse_world_file(std::span<const std::uint8_t> bytes, const std::string& name,
                           const WorldFileReadOptions& options) {
  detail::ByteReader r(bytes, name);
  Budget budget(name, options.memory_limit_bytes);
  if (bytes.size() < 20 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    r.fail_at(0, "not a voxfield world file (bad magic)");
  r.skip(8, "magic");
  WorldFile out;
  out.version = get<std::uint32_t>(r, "version");
  const auto sections = get<std::uint32_t>(r, "section count");
  const auto header_crc = get<std::uint32_t>(r, "header checksum");
  if (header_crc != crc(bytes.data(), 16)) r.fail_at(0, "header checksum mismatch (corrupt file)");
  if (out.version > kWorldFileVersion) {
    r.fail_at(8, "written by a newer voxfield (format version " + std::to_string(out.version) +
                     "); this build reads versions up to " + std::to_string(kWorldFileVersion));
  }
  if (out.version == 0) r.fail_at(8, "invalid format version 0");
  if (sections == 0 || sections > 1024)
    r.fail_at(12, "invalid section count " + std::to_string(sections));
  for (std::uint32_t s = 0; s < sections; ++s) {
    const std::uint64_t at = r.offset();
    const auto kind = get<std::uint32_t>(r, "section kind");
    const auto size = get<std::uint64_t>(r, "section size");
    if (size > r.remaining())
      r.fail_at(at, "section of " + std::to_string(size) + " bytes overruns the file");
    detail::ByteReader payload = r.sub(static_cast<std::size_t>(size), "section");
    const auto stored = get<std::uint32_t>(r, "section checksum");
    if (stored != crc(bytes.data() + at + 12, static_cast<std::size_t>(size)))
      r.fail_at(at, "section checksum mismatch (corrupt file)");
    if (kind == kWorldSection) {
      if (s != 0) r.fail_at(at, "the world section must come first");
      for (Rgba& c : out.world.palette) c = get<Rgba>(payload, "palette");
      ChunkFilter filter;
      if (options.keep_z) filter = {false, options.keep_z->first, options.keep_z->second};
      out.world.voxels = get_grid<std::uint8_t>(payload, budget, filter, &out.stored_chunks_box);
    } else if (kind == kFrameSection) {
      if (s != 1 || out.version < 2)
        r.fail_at(at, "a frame section that does not follow the world (or in a version 1 file)");
      out.world.frame = get_frame(payload, at);
    } else if (kind == kFieldSection) {
      if (s == 0) r.fail_at(at, "a field section before the world");
      if (options.keep_z) {  // a slab of the world only: the field's bytes are checked, not read
        payload.skip(payload.remaining(), "field");
        continue;
      }
      out.fields.push_back(get_field(payload, budget));
      const DistanceField& f = out.fields.back();
      const int edge = out.world.voxels.chunk_edge();
      if (f.chunk_edge() != edge || (f.sites && f.sites->chunk_edge() != edge)) {
        r.fail_at(at, "a field stored in chunks of another edge than its world's (" +
                          std::to_string(edge) + ")");
      }
    } else {
      r.fail_at(at, "unknown section kind " + std::to_string(kind));
    }
    if (!payload.at_end()) r.fail_at(payload.offset(), "trailing bytes in a section");
  }
  if (!r.at_end()) r.fail("trailing bytes after the last section");
  for (DistanceField& f : out.fields) f.frame = out.world.frame;
  return out;
}

void write_world_file(const World& world, const std::filesystem::path& path,
                      const std::vector<const DistanceField*>& fields) {
  write_file_atomic(path, encode_world_file(world, fields));
}

WorldFile read_world_file(const std::filesystem::path& path, const WorldFileReadOptions& options) {
  const auto bytes = read_file(path, effective_memory_limit(options.memory_limit_bytes));
  WorldFileReadOptions rest = options;  // what the file's bytes leave for what they decode to
  rest.memory_limit_bytes = remaining_memory(options.memory_limit_bytes, bytes.size());
  return parse_world_file(bytes, path.string(), rest);
}

}  // namespace voxfield
