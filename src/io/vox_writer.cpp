// voxfield — MagicaVoxel .vox writer (version 200 with a scene graph).
//
// The world's content is cut into regions of at most 256^3 voxels (XYZI stores coordinates in one
// byte each). Each non-empty region becomes one model, trimmed to its content, and is placed by
// its own nTRN so that the reader's placement rule floor(T + v - floor(size/2) + 0.5) = T + v -
// floor(size/2) puts voxel v back where it came from.
#include <algorithm>
#include <cstring>
#include <string>
#include <tuple>

#include "voxfield/file.h"
#include "voxfield/vox.h"

namespace voxfield {
namespace {

constexpr int kMaxWrittenModelEdge = 256;

class Writer {
 public:
  std::vector<std::uint8_t> bytes;

  void u32(std::uint32_t v) {
    std::uint8_t b[4];
    std::memcpy(b, &v, 4);
    bytes.insert(bytes.end(), b, b + 4);
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void raw(const char* s, std::size_t n) { bytes.insert(bytes.end(), s, s + n); }
  void string(const std::string& s) {
    i32(static_cast<std::int32_t>(s.size()));
    raw(s.data(), s.size());
  }
  void dict(const std::vector<std::pair<std::string, std::string>>& d) {
    i32(static_cast<std::int32_t>(d.size()));
    for (const auto& [k, v] : d) {
      string(k);
      string(v);
    }
  }
  // Starts a chunk without children; returns the position of its content-size field.
  std::size_t begin_chunk(const char id[4]) {
    raw(id, 4);
    const std::size_t at = bytes.size();
    u32(0);
    u32(0);
    return at;
  }
  void end_chunk(std::size_t at) {
    const std::uint32_t size = static_cast<std::uint32_t>(bytes.size() - at - 8);
    std::memcpy(bytes.data() + at, &size, 4);
  }
};

struct Region {
  Box3i box;  // trimmed to content
};

}  // namespace

std::vector<std::uint8_t> encode_vox(const World& world) {
  const Grid<std::uint8_t>& g = world.voxels;
  // Tiles of 256^3 aligned to multiples of 256: every chunk edge (8..128) divides 256, so each
  // stored chunk lies in exactly one tile, and only tiles holding chunks are visited. Within a
  // tile only the box covering its stored chunks is read: a 20^3 model costs a chunk or two, not
  // the 16 Mi voxels of its tile.
  struct TileChunks {
    Vec3i tile;
    Box3i chunks;  // the union of the tile's stored chunk boxes
  };
  static_assert(kMaxWrittenModelEdge == 1 << 8, "tiles are found by shifting coordinates by 8");
  std::vector<TileChunks> tiles;
  for (const Vec3i c : g.chunk_coords()) {
    const Box3i box = g.chunk_box(c);
    tiles.push_back({{box.begin.x >> 8, box.begin.y >> 8, box.begin.z >> 8}, box});
  }
  std::sort(tiles.begin(), tiles.end(), [](const TileChunks& a, const TileChunks& b) {
    return std::tie(a.tile.z, a.tile.y, a.tile.x) < std::tie(b.tile.z, b.tile.y, b.tile.x);
  });
  std::vector<TileChunks> merged;
  for (const TileChunks& t : tiles) {
    if (merged.empty() || !(merged.back().tile == t.tile)) {
      merged.push_back(t);
      continue;
    }
    Box3i& u = merged.back().chunks;
    u = {{std::min(u.begin.x, t.chunks.begin.x), std::min(u.begin.y, t.chunks.begin.y),
          std::min(u.begin.z, t.chunks.begin.z)},
         {std::max(u.end.x, t.chunks.end.x), std::max(u.end.y, t.chunks.end.y),
          std::max(u.end.z, t.chunks.end.z)}};
  }

  // Trim each tile to its content.
  std::vector<Region> regions;
  std::vector<std::uint8_t> dense;
  for (const TileChunks& t : merged) {
    const Box3i& box = t.chunks;
    dense.resize(static_cast<std::size_t>(box.volume()));
    g.copy_to_dense(box, dense.data());
    Vec3i lo = box.end, hi = box.begin - Vec3i::splat(1);
    const Vec3i s = box.size();
    std::size_t i = 0;
    for (int zz = 0; zz < s.z; ++zz)
      for (int yy = 0; yy < s.y; ++yy)
        for (int xx = 0; xx < s.x; ++xx, ++i) {
          if (!dense[i]) continue;
          const Vec3i p = box.begin + Vec3i{xx, yy, zz};
          lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
          hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
    if (hi.x >= lo.x) regions.push_back({Box3i::from_inclusive(lo, hi)});
  }

  Writer w;
  w.raw("VOX ", 4);
  w.i32(200);
  w.raw("MAIN", 4);
  w.u32(0);
  const std::size_t main_children = w.bytes.size();
  w.u32(0);

  // Models.
  auto write_model = [&](const Box3i& box) {
    const Vec3i s = box.size();
    std::size_t at = w.begin_chunk("SIZE");
    w.i32(s.x);
    w.i32(s.y);
    w.i32(s.z);
    w.end_chunk(at);
    at = w.begin_chunk("XYZI");
    const std::size_t count_at = w.bytes.size();
    w.u32(0);
    dense.resize(static_cast<std::size_t>(box.volume()));
    g.copy_to_dense(box, dense.data());
    std::uint32_t count = 0;
    std::size_t i = 0;
    for (int z = 0; z < s.z; ++z)
      for (int y = 0; y < s.y; ++y)
        for (int x = 0; x < s.x; ++x, ++i) {
          if (!dense[i]) continue;
          const std::uint8_t v[4] = {static_cast<std::uint8_t>(x), static_cast<std::uint8_t>(y),
                                     static_cast<std::uint8_t>(z), dense[i]};
          w.bytes.insert(w.bytes.end(), v, v + 4);
          ++count;
        }
    std::memcpy(w.bytes.data() + count_at, &count, 4);
    w.end_chunk(at);
  };
  if (regions.empty()) {
    // MagicaVoxel expects at least one model: an empty 1^3 one.
    std::size_t at = w.begin_chunk("SIZE");
    w.i32(1);
    w.i32(1);
    w.i32(1);
    w.end_chunk(at);
    at = w.begin_chunk("XYZI");
    w.u32(0);
    w.end_chunk(at);
  }
  for (const Region& r : regions) write_model(r.box);
  const int model_count = regions.empty() ? 1 : static_cast<int>(regions.size());

  // Scene graph: nTRN 0 -> nGRP 1 -> (nTRN 2k+2 -> nSHP 2k+3) per model, all on layer 0.
  std::size_t at = w.begin_chunk("nTRN");
  w.i32(0);
  w.dict({});
  w.i32(1);
  w.i32(-1);
  w.i32(-1);
  w.i32(1);
  w.dict({});
  w.end_chunk(at);
  at = w.begin_chunk("nGRP");
  w.i32(1);
  w.dict({});
  w.i32(model_count);
  for (int k = 0; k < model_count; ++k) w.i32(2 * k + 2);
  w.end_chunk(at);
  for (int k = 0; k < model_count; ++k) {
    Vec3i t{0, 0, 0};
    if (!regions.empty()) {
      const Box3i& b = regions[static_cast<std::size_t>(k)].box;
      const Vec3i s = b.size();
      t = b.begin + Vec3i{s.x / 2, s.y / 2, s.z / 2};
    }
    at = w.begin_chunk("nTRN");
    w.i32(2 * k + 2);
    w.dict({});
    w.i32(2 * k + 3);
    w.i32(-1);
    w.i32(0);
    w.i32(1);
    w.dict({{"_t", std::to_string(t.x) + " " + std::to_string(t.y) + " " + std::to_string(t.z)}});
    w.end_chunk(at);
    at = w.begin_chunk("nSHP");
    w.i32(2 * k + 3);
    w.dict({});
    w.i32(1);
    w.i32(k);
    w.dict({});
    w.end_chunk(at);
  }
  at = w.begin_chunk("LAYR");
  w.i32(0);
  w.dict({});
  w.i32(-1);
  w.end_chunk(at);

  // Palette: chunk entry i is material i + 1.
  at = w.begin_chunk("RGBA");
  for (int i = 0; i < 256; ++i) {
    const Rgba c = i < 255 ? world.palette[static_cast<std::size_t>(i + 1)] : Rgba{};
    const std::uint8_t v[4] = {c.r, c.g, c.b, c.a};
    w.bytes.insert(w.bytes.end(), v, v + 4);
  }
  w.end_chunk(at);

  const std::uint32_t children = static_cast<std::uint32_t>(w.bytes.size() - main_children - 4);
  std::memcpy(w.bytes.data() + main_children, &children, 4);
  return std::move(w.bytes);
}

void write_vox(const World& world, const std::filesystem::path& path) {
  write_file_atomic(path, encode_vox(world));
}

}  // namespace voxfield
