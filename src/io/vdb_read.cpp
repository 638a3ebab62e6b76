// voxfield — reading .vdb files (OpenVDB's file formats 222 to 225; Museth, "VDB: High-resolution
// sparse volumes with dynamic topology", ACM TOG 2013) with voxfield's own bounds-checked parser:
// the header, the file's metadata, then per grid a descriptor (name, tree type, instance parent
// and, in files, the offsets of the grid's blocks), its compression flags, metadata and transform,
// and its tree (vdb_read_tree.cpp). Written without OpenVDB so that damaged or hostile files get
// a FormatError naming the file and offset, where OpenVDB 10 aborts the process.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "byte_reader.h"
#include "vdb_read_tree.h"
#include "voxfield/error.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/vdb.h"

namespace voxfield {
namespace {

using detail::ByteReader;

constexpr std::uint64_t kVdbMagic = 0x56444220;  // "VDB " as OpenVDB writes it, in an int64
constexpr std::uint32_t kOldestFormat = 222;     // per-grid compression, node mask compression
constexpr std::uint32_t kNewestFormat = 225;     // OpenVDB 12's half grids

std::string read_string(ByteReader& r, const char* what) {
  const std::uint32_t n = r.u32(what);
  const auto bytes = r.take(n, what);
  return std::string(bytes.begin(), bytes.end());
}

// The numbers a metadata type holds and the bytes of each, or 0 for a type read as text / raw.
struct MetaLayout {
  const char* type;
  int count;
  int bytes;
  char kind;  // 'i' signed integer, 'f' IEEE float, 'b' bool
};
constexpr MetaLayout kMetaLayouts[] = {
    {"bool", 1, 1, 'b'},   {"int32", 1, 4, 'i'}, {"int64", 1, 8, 'i'},  {"float", 1, 4, 'f'},
    {"double", 1, 8, 'f'}, {"vec2i", 2, 4, 'i'}, {"vec2s", 2, 4, 'f'},  {"vec2d", 2, 8, 'f'},
    {"vec3i", 3, 4, 'i'},  {"vec3s", 3, 4, 'f'}, {"vec3d", 3, 8, 'f'},  {"vec4i", 4, 4, 'i'},
    {"vec4s", 4, 4, 'f'},  {"vec4d", 4, 8, 'f'}, {"mat4s", 16, 4, 'f'}, {"mat4d", 16, 8, 'f'},
};

double decode_number(const std::uint8_t* p, int bytes, char kind) {
  if (kind == 'b') return p[0] != 0 ? 1 : 0;
  if (kind == 'i') {
    if (bytes == 4) {
      std::int32_t v;
      std::memcpy(&v, p, 4);
      return v;
    }
    std::int64_t v;
    std::memcpy(&v, p, 8);
    return static_cast<double>(v);
  }
  if (bytes == 4) {
    float v;
    std::memcpy(&v, p, 4);
    return v;
  }
  double v;
  std::memcpy(&v, p, 8);
  return v;
}

// MetaMap::readMeta: a count, then per item its name, type name, size and value.
std::map<std::string, VdbMetadata> read_metadata(ByteReader& r) {
  std::map<std::string, VdbMetadata> out;
  const std::uint32_t count = r.u32("metadata count");
  if (count > r.remaining() / 12) r.fail("more metadata items than bytes left");
  for (std::uint32_t i = 0; i < count; ++i) {
    std::string name = read_string(r, "metadata name");
    VdbMetadata m;
    m.type = read_string(r, "metadata type");
    const std::uint64_t at = r.offset();
    const std::uint32_t size = r.u32("metadata size");
    const auto bytes = r.take(size, "metadata value");
    if (m.type == "string") {
      m.text.assign(bytes.begin(), bytes.end());
    } else {
      for (const MetaLayout& l : kMetaLayouts) {
        if (m.type != l.type) continue;
        if (size != static_cast<std::uint32_t>(l.count * l.bytes))
          r.fail_at(at, "metadata \"" + name + "\" of type " + m.type + " holds " +
                            std::to_string(size) + " bytes (expected " +
                            std::to_string(l.count * l.bytes) + ")");
        for (int k = 0; k < l.count; ++k)
          m.numbers.push_back(decode_number(bytes.data() + k * l.bytes, l.bytes, l.kind));
      }
    }
    out[std::move(name)] = std::move(m);
  }
  return out;
}

// "Tree_float_5_4_3" (and "_HalfFloat", stripped by the caller) into the value type and levels.
bool parse_tree_type(const std::string& type, VdbGrid& g) {
  constexpr std::string_view kPrefix = "Tree_";
  if (type.rfind(kPrefix, 0) != 0) return false;
  std::string_view rest = std::string_view(type).substr(kPrefix.size());
  const std::size_t sep = rest.find('_');
  if (sep == std::string_view::npos) return false;
  const std::string_view value = rest.substr(0, sep);
  struct Named {
    std::string_view name;
    VdbValueType type;
    int components;
  };
  constexpr Named kTypes[] = {{"float", VdbValueType::kFloat, 1},
                              {"double", VdbValueType::kDouble, 1},
                              {"bool", VdbValueType::kBool, 1},
                              {"int32", VdbValueType::kInt32, 1},
                              {"vec3s", VdbValueType::kVec3f, 3}};
  const auto it = std::find_if(std::begin(kTypes), std::end(kTypes),
                               [&](const Named& n) { return n.name == value; });
  if (it == std::end(kTypes)) return false;
  g.value_type = it->type;
  g.components = it->components;
  g.log2_dims.clear();
  rest = rest.substr(sep + 1);
  while (!rest.empty()) {
    int d = 0;
    const auto [end, ec] = std::from_chars(rest.data(), rest.data() + rest.size(), d);
    if (ec != std::errc{}) return false;
    g.log2_dims.push_back(d);
    rest = rest.substr(static_cast<std::size_t>(end - rest.data()));
    if (!rest.empty()) {
      if (rest[0] != '_') return false;
      rest = rest.substr(1);
    }
  }
  // Two to four levels below the root, each node 2^1 to 2^7 per edge, a root child at most 2^20
  // voxels per edge: every configuration OpenVDB ships (5_4_3, 4_3, 5_5_3...) and no node whose
  // masks alone would be megabytes.
  int total = 0;
  for (int d : g.log2_dims) {
    if (d < 1 || d > 7) return false;
    total += d;
  }
  if (g.log2_dims.size() < 2 || g.log2_dims.size() > 4 || total > 20) return false;
  g.leaf_edge = 1 << g.log2_dims.back();
  return true;
}

// A map (math/Maps.h) as index-to-world: world = m * (i, j, k, 1).
void read_transform(ByteReader& r, VdbGrid& g) {
  const std::uint64_t at = r.offset();
  const std::string type = read_string(r, "transform type");
  auto vec3 = [&](const char* what) {
    return std::array<double, 3>{r.f64(what), r.f64(what), r.f64(what)};
  };
  std::array<double, 12> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  auto scale_translate = [&](const std::array<double, 3>& scale,
                             const std::array<double, 3>& translate) {
    for (int a = 0; a < 3; ++a) {
      m[4 * a + a] = scale[a];
      m[4 * a + 3] = translate[a];
    }
  };
  if (type == "ScaleMap" || type == "UniformScaleMap") {
    const auto scale = vec3("scale");
    for (int k = 0; k < 4; ++k) vec3("derived scale");  // voxel size, inverses, kept by OpenVDB
    scale_translate(scale, {0, 0, 0});
  } else if (type == "ScaleTranslateMap" || type == "UniformScaleTranslateMap") {
    const auto translate = vec3("translation");
    const auto scale = vec3("scale");
    for (int k = 0; k < 4; ++k) vec3("derived scale");
    scale_translate(scale, translate);
  } else if (type == "TranslationMap") {
    scale_translate({1, 1, 1}, vec3("translation"));
  } else if (type == "AffineMap" || type == "UnitaryMap") {
    // A Mat4d applied to row vectors: world = (i, j, k, 1) * M, the translation in row 3.
    double rows[4][4];
    for (auto& row : rows)
      for (double& v : row) v = r.f64("matrix");
    for (int a = 0; a < 3; ++a)
      for (int c = 0; c < 4; ++c) m[4 * a + c] = rows[c][a];
  } else {
    r.fail_at(at, "transform \"" + type +
                      "\" is not read (voxfield reads scale, translation and affine maps; not "
                      "frustums)");
  }
  for (double v : m)
    if (!std::isfinite(v)) r.fail_at(at, "a transform with a non-finite entry");
  g.index_to_world = m;
  for (int c = 0; c < 3; ++c) g.voxel_size[c] = std::hypot(m[c], m[4 + c], m[8 + c]);
  if (!(g.voxel_size[0] > 0 && g.voxel_size[1] > 0 && g.voxel_size[2] > 0))
    r.fail_at(at, "a transform with a zero voxel size");
}

// What a grid's tree and a metadata map hold in memory, as the memory limit counts them.
std::uint64_t tree_bytes(const VdbGrid& g) {
  std::uint64_t n = g.leaf_floats.size() * sizeof(float) + g.leaf_doubles.size() * sizeof(double) +
                    g.tiles.size() * sizeof(VdbTile);
  for (const VdbLeaf& l : g.leaves) n += sizeof(VdbLeaf) + l.active_bits.size() * 8;
  return n;
}
std::uint64_t metadata_bytes(const std::map<std::string, VdbMetadata>& m) {
  std::uint64_t n = 0;
  for (const auto& [key, value] : m)
    n += 64 + key.size() + value.type.size() + value.text.size() + value.numbers.size() * 8;
  return n;
}

struct Descriptor {
  std::string unique_name, type, parent;
  bool half = false;
  std::int64_t grid_pos = 0, block_pos = 0, end_pos = 0;
};

Descriptor read_descriptor(ByteReader& r) {
  Descriptor d;
  d.unique_name = read_string(r, "grid name");
  d.type = read_string(r, "grid type");
  constexpr std::string_view kHalf = "_HalfFloat";
  if (d.type.size() > kHalf.size() && d.type.ends_with(kHalf)) {
    d.half = true;
    d.type.resize(d.type.size() - kHalf.size());
  }
  d.parent = read_string(r, "instance parent name");
  return d;
}

std::string strip_suffix(const std::string& unique) {
  return unique.substr(0, unique.find('\x1e'));  // OpenVDB's separator before a duplicate's index
}

}  // namespace

VdbFile decode_vdb(std::span<const std::uint8_t> bytes, const std::string& name,
                   const VdbReadOptions& options) {
  ByteReader r(bytes, name);
  VdbFile file;
  if (r.u64("magic") != kVdbMagic) r.fail_at(0, "not an OpenVDB file (bad magic)");
  file.format_version = r.u32("file format version");
  if (file.format_version < kOldestFormat || file.format_version > kNewestFormat)
    r.fail_at(8, "OpenVDB file format " + std::to_string(file.format_version) +
                     " (voxfield reads 222 to 225: OpenVDB 3 to 12)");
  file.library_major = r.u32("library version");
  file.library_minor = r.u32("library version");
  const bool has_offsets = r.u8("grid offsets flag") != 0;
  r.skip(36, "UUID");
  file.metadata = read_metadata(r);
  const std::uint64_t count_at = r.offset();
  const std::int32_t count = r.i32("grid count");
  if (count < 0 || static_cast<std::uint64_t>(count) > r.remaining() / 12)
    r.fail_at(count_at, "grid count " + std::to_string(count) + " does not fit the file");
  std::uint64_t used = metadata_bytes(file.metadata);
  std::unordered_map<std::string, std::size_t> read_grids;  // unique name -> index in file.grids
  for (std::int32_t i = 0; i < count; ++i) {
    const std::uint64_t desc_at = r.offset();
    Descriptor d = read_descriptor(r);
    // Every descriptor carries the offsets; streams (no grid offsets) write zeros.
    d.grid_pos = r.i64("grid offset");
    d.block_pos = r.i64("grid block offset");
    d.end_pos = r.i64("grid end offset");
    // In a file, a grid is read within [grid offset, end offset) and the next descriptor from
    // the end offset: a grid follows its descriptor (Archive::write), so every byte is read once.
    std::optional<ByteReader> body;
    if (has_offsets) {
      if (d.grid_pos < 0 || static_cast<std::uint64_t>(d.grid_pos) < r.offset() ||
          d.end_pos < d.grid_pos || static_cast<std::uint64_t>(d.end_pos) > bytes.size())
        r.fail_at(desc_at,
                  "grid \"" + strip_suffix(d.unique_name) + "\" has offsets outside the file");
      r.seek(static_cast<std::uint64_t>(d.grid_pos), "grid");
      body.emplace(r.sub(static_cast<std::size_t>(d.end_pos - d.grid_pos), "grid"));
    }
    ByteReader& in = body ? *body : r;
    VdbGrid g;
    g.name = strip_suffix(d.unique_name);
    g.type_name = d.type;
    g.half_float = d.half;
    g.instance_of = strip_suffix(d.parent);
    if (!parse_tree_type(d.type, g)) {
      if (!has_offsets)
        r.fail_at(desc_at, "grid \"" + g.name + "\" of type " + d.type +
                               ": voxfield reads float, double, bool, int32 and vec3s trees "
                               "(and cannot skip a grid in a file without grid offsets)");
      continue;  // another kind of grid (points, masks...): skipped, as its offsets allow
    }
    detail::VdbTreeReading how;
    how.format_version = file.format_version;
    how.compression = in.u32("grid compression flags");
    how.memory_limit_bytes = options.memory_limit_bytes;
    how.used_bytes = &used;
    how.clip = options.clip;
    g.metadata = read_metadata(in);
    used = add_sat(used, metadata_bytes(g.metadata));
    if (auto it = g.metadata.find("class"); it != g.metadata.end()) g.grid_class = it->second.text;
    if (g.grid_class.empty()) g.grid_class = "unknown";
    read_transform(in, g);
    if (d.parent.empty()) {
      detail::read_vdb_tree(in, g, how);
    } else {
      // An instance shares the tree of a grid read before it (Archive::connectInstance).
      const auto parent = read_grids.find(d.parent);
      if (parent == read_grids.end())
        r.fail_at(desc_at, "grid \"" + g.name + "\" instances \"" + g.instance_of +
                               "\", which is not a float, double, bool, int32 or vec3s grid "
                               "before it");
      const VdbGrid& p = file.grids[parent->second];
      if (p.type_name != g.type_name)
        r.fail_at(desc_at, "grid \"" + g.name + "\" instances a grid of another type");
      used = add_sat(used, tree_bytes(p));
      if (used > effective_memory_limit(options.memory_limit_bytes))
        require_memory(used, options.memory_limit_bytes, name, "its instanced grids");
      g.background = p.background;
      g.tiles = p.tiles;
      g.leaves = p.leaves;
      g.leaf_floats = p.leaf_floats;
      g.leaf_doubles = p.leaf_doubles;
      g.clip = p.clip;
      g.dropped_stored = p.dropped_stored;
      g.dropped_active = p.dropped_active;
    }
    read_grids[d.unique_name] = file.grids.size();
    file.grids.push_back(std::move(g));
  }
  return file;
}

std::uint64_t VdbFile::memory_bytes() const {
  std::uint64_t n = metadata_bytes(metadata);
  for (const VdbGrid& g : grids) n = add_sat(n, add_sat(tree_bytes(g), metadata_bytes(g.metadata)));
  return n;
}

VdbFile read_vdb(const std::filesystem::path& path, const VdbReadOptions& options) {
  const std::uint64_t limit = effective_memory_limit(options.memory_limit_bytes);
  const std::vector<std::uint8_t> bytes = read_file(path, limit);
  VdbReadOptions rest = options;  // the file's bytes are held while its trees are decoded
  rest.memory_limit_bytes = remaining_memory(limit, bytes.size());
  return decode_vdb(bytes, path.string(), rest);
}

const char* vdb_value_type_name(VdbValueType t) {
  switch (t) {
    case VdbValueType::kFloat:
      return "float";
    case VdbValueType::kDouble:
      return "double";
    case VdbValueType::kBool:
      return "bool";
    case VdbValueType::kInt32:
      return "int32";
    case VdbValueType::kVec3f:
      return "vec3s";
  }
  return "?";
}

}  // namespace voxfield
