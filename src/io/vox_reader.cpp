// voxfield — MagicaVoxel .vox reader.
//
// Format: MagicaVoxel's published file-format notes (vox format 150, extension for the scene graph
// in 200), read defensively: every length is checked against its parent before use, counts are
// checked against the bytes that could hold them before anything is allocated, and the scene graph
// is walked with a depth and instance budget so that cycles and exponential instancing fail
// cleanly instead of hanging.
#include <zlib.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "byte_reader.h"
#include "vox_affine.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/vox.h"

namespace voxfield {
namespace {

using detail::Affine;
using detail::ByteReader;

constexpr int kMaxModelEdge = 1024;        // MagicaVoxel writes at most 256; leave room for others
constexpr int kMaxSceneDepth = 64;         // nesting of nTRN/nGRP; real files use < 10
constexpr std::int64_t kMaxInstances = 1 << 20;
constexpr std::int64_t kMaxVisits = 1 << 22;  // node visits: bounds DAGs that instance exponentially
constexpr std::int64_t kMaxPlacedVoxels = std::int64_t{1} << 32;
constexpr std::int64_t kMaxTranslation = std::int64_t{1} << 30;  // one nTRN's _t component
constexpr int kMinVersion = 150;                                 // the oldest documented format
// What the reader itself keeps per item, for the memory estimate (the world's chunks are
// counted separately): a stored voxel of an XYZI model, a placed instance (its record and
// placement), a chunk of the world beyond its voxels (hash node and bookkeeping).
constexpr std::uint64_t kBytesPerStoredVoxel = 8;
constexpr std::uint64_t kBytesPerInstance = 192;
constexpr std::uint64_t kBytesPerChunkNode = 96;

using Dict = std::vector<std::pair<std::string, std::string>>;

std::optional<std::string> lookup(const Dict& d, std::string_view key) {
  for (const auto& [k, v] : d)
    if (k == key) return v;
  return std::nullopt;
}

std::string read_string(ByteReader& r) {
  const std::int32_t n = r.i32("string length");
  if (n < 0 || static_cast<std::size_t>(n) > r.remaining()) {
    r.fail("string length " + std::to_string(n) + " overruns its chunk");
  }
  auto s = r.take(static_cast<std::size_t>(n), "string");
  return std::string(s.begin(), s.end());
}

Dict read_dict(ByteReader& r) {
  const std::int32_t n = r.i32("dictionary size");
  // Each entry needs at least two 4-byte string lengths.
  if (n < 0 || static_cast<std::uint64_t>(n) * 8 > r.remaining()) {
    r.fail("dictionary of " + std::to_string(n) + " entries overruns its chunk");
  }
  Dict d;
  d.reserve(static_cast<std::size_t>(n));
  for (std::int32_t i = 0; i < n; ++i) {
    std::string k = read_string(r);
    std::string v = read_string(r);
    d.emplace_back(std::move(k), std::move(v));
  }
  return d;
}

// Reads a count that must be non-negative and small enough for `bytes_each` bytes per item to fit
// in what is left of the chunk.
std::int32_t read_count(ByteReader& r, std::size_t bytes_each, const char* what) {
  const std::int32_t n = r.i32(what);
  if (n < 0 || static_cast<std::uint64_t>(n) * bytes_each > r.remaining()) {
    r.fail(std::string(what) + " " + std::to_string(n) + " overruns its chunk");
  }
  return n;
}

struct ModelData {
  VoxModelInfo info;
  // Solid voxels as (x, y, z, colour index); colour 0 (air) is dropped at load.
  struct Voxel {
    std::uint16_t x, y, z;
    std::uint8_t c;
  };
  std::vector<Voxel> voxels;  // XYZI models, and TDCZ models that are mostly air
  // TDCZ models at least an eighth solid: one colour index per voxel of the SIZE box, x fastest
  // (a voxel list would take 8 bytes per solid voxel of a model that can hold 2^30).
  std::vector<std::uint8_t> dense;  // empty: the model is in `voxels`

  std::int64_t solid_count() const { return info.voxel_count; }
  // Calls f(x, y, z, colour) for every solid voxel.
  template <class F>
  void for_each_voxel(F&& f) const {
    if (dense.empty()) {
      for (const Voxel& v : voxels) f(v.x, v.y, v.z, v.c);
      return;
    }
    std::size_t i = 0;
    for (int z = 0; z < info.size.z; ++z)
      for (int y = 0; y < info.size.y; ++y)
        for (int x = 0; x < info.size.x; ++x, ++i)
          if (dense[i] != 0) f(x, y, z, dense[i]);
  }
};

struct Node {
  enum Kind { kTransform, kGroup, kShape };
  Node(Kind k, std::uint64_t at) : kind(k), offset(at) {}
  Kind kind;
  std::uint64_t offset;  // of its chunk, for error messages
  Dict attributes;
  // transform
  std::int32_t child = -1;
  std::int32_t layer = -1;
  Affine frame0;
  // group
  std::vector<std::int32_t> children;
  // shape
  std::int32_t model = -1;
};

Affine parse_frame(const Dict& frame, ByteReader& r) {
  Affine a;
  if (auto rot = lookup(frame, "_r")) {
    int bits = -1;
    auto [p, ec] = std::from_chars(rot->data(), rot->data() + rot->size(), bits);
    if (ec != std::errc() || p != rot->data() + rot->size() || bits < 0 || bits > 127) {
      r.fail("bad rotation \"" + *rot + "\" (expected an integer 0..127)");
    }
    const int c0 = bits & 3, c1 = (bits >> 2) & 3;
    if (c0 > 2 || c1 > 2 || c0 == c1) r.fail("rotation " + *rot + " is not a permutation");
    const int c2 = 3 - c0 - c1;
    const int cols[3] = {c0, c1, c2};
    for (int i = 0; i < 3; ++i) {
      a.r[i] = {0, 0, 0};
      a.r[i][cols[i]] = ((bits >> (4 + i)) & 1) ? -1 : 1;
    }
  }
  if (auto tr = lookup(frame, "_t")) {
    const char* p = tr->data();
    const char* end = p + tr->size();
    for (int k = 0; k < 3; ++k) {
      while (p < end && *p == ' ') ++p;
      std::int64_t v = 0;
      auto res = std::from_chars(p, end, v);
      if (res.ec != std::errc() || v < -kMaxTranslation || v > kMaxTranslation) {
        r.fail("bad translation \"" + *tr + "\" (expected three integers within +-2^30)");
      }
      a.t[k] = v;
      p = res.ptr;
    }
    while (p < end && *p == ' ') ++p;
    if (p != end) r.fail("bad translation \"" + *tr + "\" (expected three integers within +-2^30)");
  }
  return a;
}

class VoxParser {
 public:
  VoxParser(std::span<const std::uint8_t> bytes, const std::string& name,
            const VoxImportOptions& options)
      : bytes_(bytes), name_(name), options_(options), result_{World(options.chunk_edge), {}} {}

  VoxImport run() {
    ByteReader r(bytes_, name_);
    if (bytes_.size() < 8) r.fail("file too short for a .vox header (" + std::to_string(bytes_.size()) + " bytes)");
    auto magic = r.take(4, "magic");
    if (!std::equal(magic.begin(), magic.end(), "VOX ")) {
      throw FormatError(name_, 0, "not a MagicaVoxel file: magic is " + printable(magic) +
                                      ", expected \"VOX \"");
    }
    result_.info.version = r.i32("version");
    if (result_.info.version < kMinVersion) {
      r.fail_at(4, "format version " + std::to_string(result_.info.version) + " is older than the oldest documented (" +
                       std::to_string(kMinVersion) + ")");
    }
    const std::uint64_t main_at = r.offset();
    const auto [id, content, children] = chunk_header(r);
    if (id != "MAIN") r.fail_at(main_at, "first chunk is \"" + id + "\", expected MAIN");
    r.skip(content, "MAIN content");
    ByteReader body = r.sub(children, "MAIN children");
    if (!r.at_end()) {
      r.fail(std::to_string(r.remaining()) + " bytes after the MAIN chunk (a damaged or concatenated file?)");
    }
    while (!body.at_end()) read_chunk(body);
    finish();
    return std::move(result_);
  }

 private:
  static std::string printable(std::span<const std::uint8_t> s) {
    std::string out = "\"";
    for (std::uint8_t c : s) {
      if (c >= 32 && c < 127) {
        out += static_cast<char>(c);
      } else {
        static const char* hex = "0123456789abcdef";
        out += "\\x";
        out += hex[c >> 4];
        out += hex[c & 15];
      }
    }
    return out + "\"";
  }

  struct Header {
    std::string id;
    std::size_t content, children;
  };
  Header chunk_header(ByteReader& r) {
    const std::uint64_t at = r.offset();
    auto id = r.take(4, "chunk id");
    const std::uint32_t content = r.u32("chunk content size");
    const std::uint32_t children = r.u32("chunk children size");
    const std::string sid(id.begin(), id.end());
    if (std::uint64_t{content} + children > r.remaining()) {
      r.fail_at(at, "chunk " + printable(id) + " declares " + std::to_string(content) + " + " +
                        std::to_string(children) + " bytes but its parent has only " +
                        std::to_string(r.remaining()) + " left");
    }
    return {sid, content, children};
  }

  void read_chunk(ByteReader& parent) {
    const std::uint64_t at = parent.offset();
    const auto [id, content_size, children_size] = chunk_header(parent);
    ByteReader c = parent.sub(content_size, "chunk content");
    parent.skip(children_size, "chunk children");
    ++result_.info.chunk_counts[id];
    if (id == "SIZE") {
      read_size(c);
    } else if (id == "XYZI") {
      read_xyzi(c, at);
    } else if (id == "TDCZ") {
      read_tdcz(c, at);
    } else if (id == "RGBA") {
      read_rgba(c);
    } else if (id == "nTRN") {
      read_transform(c, at);
    } else if (id == "nGRP") {
      read_group(c, at);
    } else if (id == "nSHP") {
      read_shape(c, at);
    } else if (id == "LAYR") {
      read_layer(c);
    }
    // PACK only announces the model count, which the SIZE chunks give anyway; everything else
    // (MATL, MATT, rOBJ, rCAM, NOTE, META, IMAP, rLIT, rAIR, rLEN, POST, rDIS, ...) carries
    // rendering settings voxfield does not use.
  }

  void read_size(ByteReader& c) {
    if (pending_size_) c.fail("SIZE chunk follows a SIZE chunk without voxel data");
    Vec3i s;
    for (int k = 0; k < 3; ++k) {
      s[k] = c.i32("model size");
      if (s[k] < 1 || s[k] > kMaxModelEdge) {
        c.fail("model size " + std::to_string(s[k]) + " outside 1.." + std::to_string(kMaxModelEdge));
      }
    }
    pending_size_ = s;
  }

  Vec3i take_size(ByteReader& c, std::uint64_t at, const char* chunk) {
    if (!pending_size_) c.fail_at(at, std::string(chunk) + " chunk without a preceding SIZE chunk");
    const Vec3i s = *pending_size_;
    pending_size_.reset();
    return s;
  }

  void read_xyzi(ByteReader& c, std::uint64_t at) {
    ModelData m;
    m.info.size = take_size(c, at, "XYZI");
    const std::int32_t n = read_count(c, 4, "voxel count");
    charge(mul_sat(static_cast<std::uint64_t>(n), kBytesPerStoredVoxel), c, at, "its models");
    m.voxels.reserve(static_cast<std::size_t>(n));
    for (std::int32_t i = 0; i < n; ++i) {
      const std::uint64_t vat = c.offset();
      auto v = c.take(4, "voxel");
      if (v[0] >= m.info.size.x || v[1] >= m.info.size.y || v[2] >= m.info.size.z) {
        c.fail_at(vat, "voxel " + std::to_string(i) + " at (" + std::to_string(v[0]) + "," +
                           std::to_string(v[1]) + "," + std::to_string(v[2]) +
                           ") lies outside the model size " + to_string(m.info.size));
      }
      if (v[3] != 0) m.voxels.push_back({v[0], v[1], v[2], v[3]});
    }
    m.info.voxel_count = static_cast<std::int64_t>(m.voxels.size());
    models_.push_back(std::move(m));
  }

  // Teardown's variant: the SIZE again, then a zlib stream (ended by a sync flush rather than a
  // final block) holding one colour index per voxel, x fastest, then y, then z.
  void read_tdcz(ByteReader& c, std::uint64_t at) {
    ModelData m;
    m.info.size = take_size(c, at, "TDCZ");
    m.info.compressed = true;
    Vec3i s;
    for (int k = 0; k < 3; ++k) s[k] = c.i32("TDCZ size");
    if (!(s == m.info.size)) {
      c.fail("TDCZ size " + to_string(s) + " differs from the SIZE chunk " + to_string(m.info.size));
    }
    const std::int64_t n = Box3i::from_size(s).volume();
    auto packed = c.take(c.remaining(), "TDCZ data");
    // deflate cannot expand more than about 1032:1; refuse to allocate for a claim beyond that.
    if (n > static_cast<std::int64_t>(packed.size()) * 1032 + 1024) {
      c.fail_at(at, "TDCZ model of " + std::to_string(n) + " voxels cannot come from " +
                        std::to_string(packed.size()) + " compressed bytes");
    }
    charge(static_cast<std::uint64_t>(n), c, at, "its models");
    std::vector<std::uint8_t> dense(static_cast<std::size_t>(n));
    z_stream z{};
    if (inflateInit(&z) != Z_OK) c.fail("cannot initialise zlib");
    z.next_in = const_cast<Bytef*>(packed.data());
    z.avail_in = static_cast<uInt>(packed.size());
    z.next_out = dense.data();
    z.avail_out = static_cast<uInt>(dense.size());
    const int rc = inflate(&z, Z_SYNC_FLUSH);
    const std::size_t produced = dense.size() - z.avail_out;
    inflateEnd(&z);
    if ((rc != Z_OK && rc != Z_STREAM_END && rc != Z_BUF_ERROR) || produced != dense.size()) {
      c.fail_at(at, "TDCZ zlib data decodes to " + std::to_string(produced) + " bytes (" +
                        (z.msg ? std::string(z.msg) : std::string("no zlib message")) +
                        "), expected " + std::to_string(n));
    }
    const std::size_t solid = dense.size() - static_cast<std::size_t>(std::count(dense.begin(), dense.end(), 0));
    m.info.voxel_count = static_cast<std::int64_t>(solid);
    if (solid * sizeof(ModelData::Voxel) <= dense.size()) {
      // Mostly air: a voxel list, so that placing the model costs its solid voxels, not its box
      // (a DAG may place one model a million times).
      std::size_t i = 0;
      for (int zc = 0; zc < s.z; ++zc)
        for (int y = 0; y < s.y; ++y)
          for (int x = 0; x < s.x; ++x, ++i)
            if (dense[i] != 0) {
              m.voxels.push_back({static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y), static_cast<std::uint16_t>(zc), dense[i]});
            }
    } else {
      m.dense = std::move(dense);  // at least an eighth solid: placing costs at most 8x its solid voxels
    }
    models_.push_back(std::move(m));
  }

  void read_rgba(ByteReader& c) {
    // Colour i of the chunk belongs to palette index i + 1; the 256th entry is unused. Some
    // writers (Teardown's) store only the 255 used entries: read what is there, keep the default
    // for the rest.
    Palette& p = result_.world.palette;
    p[0] = {};
    const std::size_t entries = std::min<std::size_t>(256, c.remaining() / 4);
    if (entries == 0) c.fail("RGBA chunk holds no colour");
    for (std::size_t i = 0; i < entries; ++i) {
      auto v = c.take(4, "palette entry");
      if (i < 255) p[i + 1] = {v[0], v[1], v[2], v[3]};
    }
    result_.info.has_palette = true;
  }

  void add_node(std::int32_t id, Node node, ByteReader& c) {
    if (id < 0) c.fail_at(node.offset, "negative node id " + std::to_string(id));
    if (!nodes_.emplace(id, std::move(node)).second) {
      c.fail_at(nodes_.at(id).offset, "duplicate scene node id " + std::to_string(id));
    }
  }

  void read_transform(ByteReader& c, std::uint64_t at) {
    Node n(Node::kTransform, at);
    const std::int32_t id = c.i32("node id");
    n.attributes = read_dict(c);
    n.child = c.i32("child node id");
    c.i32("reserved id");
    n.layer = c.i32("layer id");
    const std::int32_t frames = read_count(c, 4, "frame count");
    for (std::int32_t f = 0; f < frames; ++f) {
      Dict frame = read_dict(c);
      // Frame 0 of an animation: the frame tagged _f = 0, else the first one.
      const auto tag = lookup(frame, "_f");
      if (f == 0 || (tag && *tag == "0")) n.frame0 = parse_frame(frame, c);
    }
    add_node(id, std::move(n), c);
  }

  void read_group(ByteReader& c, std::uint64_t at) {
    Node n(Node::kGroup, at);
    const std::int32_t id = c.i32("node id");
    n.attributes = read_dict(c);
    const std::int32_t count = read_count(c, 4, "child count");
    n.children.resize(static_cast<std::size_t>(count));
    for (auto& child : n.children) child = c.i32("child node id");
    add_node(id, std::move(n), c);
  }

  void read_shape(ByteReader& c, std::uint64_t at) {
    Node n(Node::kShape, at);
    const std::int32_t id = c.i32("node id");
    n.attributes = read_dict(c);
    const std::int32_t count = read_count(c, 8, "model count");
    for (std::int32_t i = 0; i < count; ++i) {
      const std::int32_t model = c.i32("model id");
      Dict attributes = read_dict(c);
      const auto tag = lookup(attributes, "_f");
      if (i == 0 || (tag && *tag == "0")) n.model = model;
    }
    if (count == 0) c.fail_at(at, "shape node " + std::to_string(id) + " references no model");
    add_node(id, std::move(n), c);
  }

  void read_layer(ByteReader& c) {
    const std::int32_t id = c.i32("layer id");
    const Dict d = read_dict(c);
    const auto hidden = lookup(d, "_hidden");
    hidden_layers_[id] = hidden && *hidden == "1";
  }

  static bool is_hidden(const Dict& d) {
    const auto h = lookup(d, "_hidden");
    return h && *h == "1";
  }

  // Walks the scene graph depth first; `name` is the _name of the nearest transform above.
  void visit(std::int32_t id, const Affine& parent, bool hidden, int depth, std::uint64_t from,
             const std::string& name) {
    ByteReader r(bytes_, name_);
    if (depth > kMaxSceneDepth) {
      r.fail_at(from, "scene graph nested deeper than " + std::to_string(kMaxSceneDepth) +
                          " levels (a cycle?)");
    }
    if (++visits_ > kMaxVisits) {
      r.fail_at(from, "scene graph walk exceeds " + std::to_string(kMaxVisits) + " node visits");
    }
    auto it = nodes_.find(id);
    if (it == nodes_.end()) r.fail_at(from, "reference to missing scene node " + std::to_string(id));
    const Node& n = it->second;
    hidden = hidden || is_hidden(n.attributes);
    switch (n.kind) {
      case Node::kTransform: {
        auto layer = hidden_layers_.find(n.layer);
        hidden = hidden || (layer != hidden_layers_.end() && layer->second);
        visit(n.child, parent.then_child(n.frame0), hidden, depth + 1, n.offset,
              lookup(n.attributes, "_name").value_or(""));
        break;
      }
      case Node::kGroup:
        for (std::int32_t child : n.children) visit(child, parent, hidden, depth + 1, n.offset, name);
        break;
      case Node::kShape:
        place_instance(n, parent, hidden, name);
        break;
    }
  }

  // Records an instance; its voxels are placed by finish() once the whole scene's cost is known.
  void place_instance(const Node& n, const Affine& xf, bool hidden, const std::string& name) {
    ByteReader r(bytes_, name_);
    if (n.model < 0 || static_cast<std::size_t>(n.model) >= models_.size()) {
      r.fail_at(n.offset, "shape references model " + std::to_string(n.model) + " but the file has " +
                              std::to_string(models_.size()));
    }
    if (static_cast<std::int64_t>(result_.info.instances.size()) >= kMaxInstances) {
      r.fail_at(n.offset, "more than " + std::to_string(kMaxInstances) + " instances");
    }
    charge(kBytesPerInstance + name.size(), r, n.offset, "its scene graph's instances");
    const ModelData& m = models_[static_cast<std::size_t>(n.model)];
    const std::array<std::int64_t, 3> pivot{m.info.size.x / 2, m.info.size.y / 2, m.info.size.z / 2};
    const auto a = xf.place({0, 0, 0}, pivot);
    const auto b = xf.place({m.info.size.x - 1, m.info.size.y - 1, m.info.size.z - 1}, pivot);
    for (int k = 0; k < 3; ++k) {
      if (!coord_in_range(std::min(a[k], b[k])) || !coord_in_range(std::max(a[k], b[k]))) {
        r.fail_at(n.offset, "instance of model " + std::to_string(n.model) + " spans " + std::to_string(std::min(a[k], b[k])) +
                                ".." + std::to_string(std::max(a[k], b[k])) + " on axis " + "xyz"[k] +
                                ", outside the supported coordinate range -2^29..2^29-1");
      }
    }
    VoxInstanceInfo inst;
    inst.model = n.model;
    inst.hidden = hidden;
    inst.name = name;
    inst.world_box = Box3i::from_inclusive(
        {static_cast<int>(std::min(a[0], b[0])), static_cast<int>(std::min(a[1], b[1])),
         static_cast<int>(std::min(a[2], b[2]))},
        {static_cast<int>(std::max(a[0], b[0])), static_cast<int>(std::max(a[1], b[1])),
         static_cast<int>(std::max(a[2], b[2]))});
    result_.info.instances.push_back(inst);
    if (hidden && !options_.include_hidden) return;
    placed_voxels_ += m.solid_count();
    if (placed_voxels_ > kMaxPlacedVoxels) {
      r.fail_at(n.offset, "scene places more than " + std::to_string(kMaxPlacedVoxels) + " voxels");
    }
    placements_.push_back({n.model, xf, n.offset, result_.info.instances.back().world_box});
  }

  // The world's chunks every placement touches, counted before any is allocated: while voxels are
  // placed each touched chunk is dense (chunk_edge^3 bytes). An instance with fewer voxels than
  // chunks in its box adds the chunks of its voxels, others every chunk of the box: an upper bound
  // within one instance's box, exact where instances are sparse (the case that costs most).
  void check_world_memory() {
    ByteReader r(bytes_, name_);
    const Grid<std::uint8_t>& g = result_.world.voxels;
    const int shift = g.chunk_shift();
    const std::uint64_t per_chunk = static_cast<std::uint64_t>(g.chunk_volume()) + kBytesPerChunkNode;
    const std::uint64_t limit = effective_memory_limit(options_.memory_limit_bytes);
    const std::uint64_t budget = limit > reader_bytes_ ? limit - reader_bytes_ : 0;
    const std::uint64_t max_chunks = budget / per_chunk;
    std::unordered_set<Vec3i, Vec3iHash> chunks;
    auto add = [&](Vec3i k, std::uint64_t at) {
      if (chunks.insert(k).second && chunks.size() > max_chunks) {
        require_memory(add_sat(reader_bytes_, mul_sat(chunks.size(), per_chunk)), limit, name_,
                       "placing its voxels (at least " + std::to_string(chunks.size()) + " chunks of " +
                           std::to_string(g.chunk_edge()) + "^3 touched, from the instance at byte " +
                           std::to_string(at) + " on)");
      }
    };
    for (const Placement& pl : placements_) {
      const ModelData& m = models_[static_cast<std::size_t>(pl.model)];
      const Vec3i lo = g.chunk_of(pl.box.begin), hi = g.chunk_of(pl.box.end - Vec3i::splat(1));
      const std::int64_t box_chunks =
          std::int64_t{hi.x - lo.x + 1} * (hi.y - lo.y + 1) * (hi.z - lo.z + 1);
      if (m.solid_count() < box_chunks) {
        const std::array<std::int64_t, 3> pivot{m.info.size.x / 2, m.info.size.y / 2, m.info.size.z / 2};
        m.for_each_voxel([&](int x, int y, int z, std::uint8_t) {
          const auto p = pl.frame.place({x, y, z}, pivot);
          add({static_cast<int>(p[0] >> shift), static_cast<int>(p[1] >> shift), static_cast<int>(p[2] >> shift)}, pl.offset);
        });
      } else {
        for (int z = lo.z; z <= hi.z; ++z)
          for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) add({x, y, z}, pl.offset);
      }
    }
    (void)r;
  }

  void finish() {
    ByteReader r(bytes_, name_);
    if (pending_size_) r.fail_at(bytes_.size(), "SIZE chunk without voxel data at end of file");
    for (const auto& m : models_) result_.info.models.push_back(m.info);
    result_.info.has_scene_graph = !nodes_.empty();
    if (!nodes_.empty()) {
      // The root is transform node 0 by convention.
      if (nodes_.find(0) == nodes_.end()) r.fail_at(8, "scene graph has no root node 0");
      visit(0, Affine{}, false, 0, nodes_.at(0).offset, "");
    } else if (!models_.empty()) {
      if (options_.frame < 0 || static_cast<std::size_t>(options_.frame) >= models_.size()) {
        throw InvalidArgument(name_ + ": frame " + std::to_string(options_.frame) +
                              " requested but the file has " + std::to_string(models_.size()) +
                              " models");
      }
      // Placed with voxel v at v: the transform that does so for the model's size.
      const ModelData& m = models_[static_cast<std::size_t>(options_.frame)];
      Affine identity;
      for (int k = 0; k < 3; ++k) identity.t[k] = m.info.size[k] / 2;
      placements_.push_back({options_.frame, identity, 8, Box3i::from_size(m.info.size)});
    }
    check_world_memory();
    for (const Placement& pl : placements_) {
      const ModelData& m = models_[static_cast<std::size_t>(pl.model)];
      const std::array<std::int64_t, 3> pivot{m.info.size.x / 2, m.info.size.y / 2, m.info.size.z / 2};
      m.for_each_voxel([&](int x, int y, int z, std::uint8_t c) {
        const auto p = pl.frame.place({x, y, z}, pivot);
        result_.world.voxels.set({static_cast<int>(p[0]), static_cast<int>(p[1]), static_cast<int>(p[2])}, c);
      });
    }
    result_.world.voxels.compact();
  }

  // Adds what the reader keeps in memory and refuses past the limit.
  void charge(std::uint64_t bytes, ByteReader& r, std::uint64_t at, const char* what) {
    reader_bytes_ = add_sat(reader_bytes_, bytes);
    if (reader_bytes_ > effective_memory_limit(options_.memory_limit_bytes)) {
      require_memory(reader_bytes_, options_.memory_limit_bytes, name_,
                     std::string("reading ") + what + " (up to byte " + std::to_string(at) + ")");
    }
    (void)r;
  }

  struct Placement {
    int model;
    Affine frame;
    std::uint64_t offset;  // of the shape node, for messages
    Box3i box;             // where the model's SIZE box lands
  };

  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  VoxImportOptions options_;
  VoxImport result_;
  std::optional<Vec3i> pending_size_;
  std::vector<ModelData> models_;
  std::unordered_map<std::int32_t, Node> nodes_;
  std::unordered_map<std::int32_t, bool> hidden_layers_;
  std::vector<Placement> placements_;
  std::int64_t placed_voxels_ = 0;
  std::int64_t visits_ = 0;
  std::uint64_t reader_bytes_ = 0;  // what the reader holds besides the world's chunks
};

}  // namespace

VoxImport parse_vox(std::span<const std::uint8_t> bytes, const std::string& name,
                    const VoxImportOptions& options) {
  return VoxParser(bytes, name, options).run();
}

VoxImport read_vox(const std::filesystem::path& path, const VoxImportOptions& options) {
  const std::vector<std::uint8_t> bytes = read_file(path, effective_memory_limit(options.memory_limit_bytes));
  VoxImportOptions rest = options;  // what the file's bytes leave for what they decode to
  rest.memory_limit_bytes = remaining_memory(options.memory_limit_bytes, bytes.size());
  return parse_vox(bytes, path.string(), rest);
}

}  // namespace voxfield
