// voxfield — MagicaVoxel .vox reader.
//
// Format: MagicaVoxel's published file-format notes (vox format 150, extension for the scene graph
// in 200), read defensively: every length is checked against its parent before use, counts are
// checked against the bytes that could hold them before anything is allocated, and the scene graph
// is walked with a depth and instance budget so that cycles and exponential instancing fail
// cleanly instead of hanging (the walk and the world's memory estimate: vox_scene.cpp).
#include <zlib.h>

#include <algorithm>
#include <charconv>
#include <optional>

#include "byte_reader.h"
#include "vox_affine.h"
#include "vox_scene.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/vox.h"

namespace voxfield {
namespace {

using detail::Affine;
using detail::ByteReader;
using detail::vox::Dict;
using detail::vox::lookup;
using detail::vox::ModelData;
using detail::vox::Node;

constexpr int kMaxReadModelEdge = 1024;  // MagicaVoxel writes at most 256; leave room for others
constexpr std::int64_t kMaxTranslation = std::int64_t{1} << 30;  // one nTRN's _t component
constexpr int kMinVersion = 150;                                 // the oldest documented format
// What the reader itself keeps per stored voxel of an XYZI model, for the memory estimate (the
// scene's instances and the world's chunks are counted by vox_scene.cpp).
constexpr std::uint64_t kBytesPerStoredVoxel = 8;

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
      : bytes_(bytes),
        name_(name),
        options_(options),
        result_{World(options.chunk_edge), {}},
        scene_(bytes, name, options_) {}

  VoxImport run() {
    ByteReader r(bytes_, name_);
    if (bytes_.size() < 8)
      r.fail("file too short for a .vox header (" + std::to_string(bytes_.size()) + " bytes)");
    auto magic = r.take(4, "magic");
    if (!std::equal(magic.begin(), magic.end(), "VOX ")) {
      throw FormatError(
          name_, 0, "not a MagicaVoxel file: magic is " + printable(magic) + ", expected \"VOX \"");
    }
    result_.info.version = r.i32("version");
    if (result_.info.version < kMinVersion) {
      r.fail_at(4, "format version " + std::to_string(result_.info.version) +
                       " is older than the oldest documented (" + std::to_string(kMinVersion) +
                       ")");
    }
    const std::uint64_t main_at = r.offset();
    const auto [id, content, children] = chunk_header(r);
    if (id != "MAIN") r.fail_at(main_at, "first chunk is \"" + id + "\", expected MAIN");
    r.skip(content, "MAIN content");
    ByteReader body = r.sub(children, "MAIN children");
    if (!r.at_end()) {
      r.fail(std::to_string(r.remaining()) +
             " bytes after the MAIN chunk (a damaged or concatenated file?)");
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
      if (s[k] < 1 || s[k] > kMaxReadModelEdge) {
        c.fail("model size " + std::to_string(s[k]) + " outside 1.." +
               std::to_string(kMaxReadModelEdge));
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
    scene_.charge(mul_sat(static_cast<std::uint64_t>(n), kBytesPerStoredVoxel), at, "its models");
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
    scene_.models.push_back(std::move(m));
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
      c.fail("TDCZ size " + to_string(s) + " differs from the SIZE chunk " +
             to_string(m.info.size));
    }
    const std::int64_t n = Box3i::from_size(s).volume();
    auto packed = c.take(c.remaining(), "TDCZ data");
    // deflate cannot expand more than about 1032:1; refuse to allocate for a claim beyond that.
    if (n > static_cast<std::int64_t>(packed.size()) * 1032 + 1024) {
      c.fail_at(at, "TDCZ model of " + std::to_string(n) + " voxels cannot come from " +
                        std::to_string(packed.size()) + " compressed bytes");
    }
    scene_.charge(static_cast<std::uint64_t>(n), at, "its models");
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
    const std::size_t solid =
        dense.size() - static_cast<std::size_t>(std::count(dense.begin(), dense.end(), 0));
    m.info.voxel_count = static_cast<std::int64_t>(solid);
    if (solid * sizeof(ModelData::Voxel) <= dense.size()) {
      // Mostly air: a voxel list, so that placing the model costs its solid voxels, not its box
      // (a DAG may place one model a million times).
      std::size_t i = 0;
      for (int zc = 0; zc < s.z; ++zc)
        for (int y = 0; y < s.y; ++y)
          for (int x = 0; x < s.x; ++x, ++i)
            if (dense[i] != 0) {
              m.voxels.push_back({static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                                  static_cast<std::uint16_t>(zc), dense[i]});
            }
    } else {
      m.dense =
          std::move(dense);  // at least an eighth solid: placing costs at most 8x its solid voxels
    }
    scene_.models.push_back(std::move(m));
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
    if (!scene_.nodes.emplace(id, std::move(node)).second) {
      c.fail_at(scene_.nodes.at(id).offset, "duplicate scene node id " + std::to_string(id));
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
    scene_.hidden_layers[id] = hidden && *hidden == "1";
  }

  void finish() {
    ByteReader r(bytes_, name_);
    if (pending_size_) r.fail_at(bytes_.size(), "SIZE chunk without voxel data at end of file");
    for (const auto& m : scene_.models) result_.info.models.push_back(m.info);
    result_.info.has_scene_graph = !scene_.nodes.empty();
    scene_.place(result_.world, result_.info);
    result_.world.voxels.compact();
  }

  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  VoxImportOptions options_;
  VoxImport result_;
  std::optional<Vec3i> pending_size_;
  detail::vox::Scene scene_;  // the models and graph read so far, and the memory they hold
};

}  // namespace

Box3i vox_extent(const VoxFileInfo& info, bool include_hidden, int frame) {
  Box3i extent;
  if (info.has_scene_graph) {
    for (const auto& inst : info.instances)
      if (include_hidden || !inst.hidden) extent = extent.unite(inst.world_box);
  } else if (frame >= 0 && static_cast<std::size_t>(frame) < info.models.size()) {
    extent = Box3i::from_size(info.models[static_cast<std::size_t>(frame)].size);
  }
  return extent;
}

VoxImport parse_vox(std::span<const std::uint8_t> bytes, const std::string& name,
                    const VoxImportOptions& options) {
  return VoxParser(bytes, name, options).run();
}

VoxImport read_vox(const std::filesystem::path& path, const VoxImportOptions& options) {
  const std::vector<std::uint8_t> bytes =
      read_file(path, effective_memory_limit(options.memory_limit_bytes));
  VoxImportOptions rest = options;  // what the file's bytes leave for what they decode to
  rest.memory_limit_bytes = remaining_memory(options.memory_limit_bytes, bytes.size());
  return parse_vox(bytes, path.string(), rest);
}

}  // namespace voxfield
