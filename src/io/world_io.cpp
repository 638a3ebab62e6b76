// voxfield — loading and saving worlds by file type (voxfield/world_io.h).
#include "voxfield/world_io.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <unordered_set>

#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/npy.h"
#include "voxfield/vdb.h"
#include "voxfield/world_file.h"

namespace voxfield {
namespace {

// Checks the first bytes against the format's magic; a mismatch is reported by the format's own
// parser (which names what it found), run on those bytes alone.
void check_magic(const std::filesystem::path& path, WorldFormat f) {
  const std::vector<std::uint8_t> head = read_file_prefix(path, 8);
  const std::string name = path.string();
  switch (f) {
    case WorldFormat::kVox:
      if (head.size() < 4 || std::memcmp(head.data(), "VOX ", 4) != 0) (void)parse_vox(head, name);
      break;
    case WorldFormat::kNpy:
      if (head.size() < 6 || std::memcmp(head.data(), "\x93NUMPY", 6) != 0)
        (void)parse_npy(head, name);
      break;
    case WorldFormat::kVfw:
      if (head.size() < 8 || std::memcmp(head.data(), "VXFWORLD", 8) != 0)
        (void)parse_world_file(head, name);
      break;
    case WorldFormat::kVdb:
      if (head.size() < 8 || std::memcmp(head.data(), "\x20\x42\x44\x56\0\0\0\0", 8) != 0)
        (void)decode_vdb(head, name);
      break;
  }
}

}  // namespace

WorldFormat world_format_of(const std::filesystem::path& path) {
  const std::string ext = lowercase_extension(path);
  if (ext == ".vox") return WorldFormat::kVox;
  if (ext == ".npy") return WorldFormat::kNpy;
  if (ext == ".vfw") return WorldFormat::kVfw;
  if (ext == ".vdb") return WorldFormat::kVdb;
  throw InvalidArgument(path.string() + ": unknown file type \"" + ext +
                        "\" (expected .vox, .npy, .vfw or .vdb)");
}

const char* world_format_name(WorldFormat f) {
  switch (f) {
    case WorldFormat::kVox:
      return "vox";
    case WorldFormat::kNpy:
      return "npy";
    case WorldFormat::kVfw:
      return "vfw";
    case WorldFormat::kVdb:
      return "vdb";
  }
  return "?";
}

LoadedWorld load_world(const std::filesystem::path& path, const LoadOptions& options) {
  const WorldFormat format = world_format_of(path);
  if (!options.vdb_grid.empty() && format != WorldFormat::kVdb)
    throw InvalidArgument(path.string() + ": a grid name ('" + options.vdb_grid +
                          "') is for .vdb files, which hold several grids");
  check_magic(path, format);
  const std::uint64_t limit = effective_memory_limit(options.memory_limit_bytes);
  const int edge =
      options.chunk_edge != 0 ? options.chunk_edge : Grid<std::uint8_t>::kDefaultChunkEdge;
  LoadedWorld out;
  out.format = format;
  switch (format) {
    case WorldFormat::kVox: {
      VoxImportOptions vo;
      vo.chunk_edge = edge;
      vo.memory_limit_bytes = limit;
      VoxImport in = read_vox(path, vo);
      out.world = std::move(in.world);
      const VoxFileInfo& info = in.info;
      out.extent = vox_extent(info);
      out.description = "MagicaVoxel .vox, version " + std::to_string(info.version);
      out.vox = std::move(in.info);
      break;
    }
    case WorldFormat::kNpy: {
      NpyReadOptions no;
      no.memory_limit_bytes = limit;
      const NpyVolume v = read_npy(path, no);
      // The volume is held while the world is built from it.
      out.world = world_from_npy(v, path.string(), edge, remaining_memory(limit, v.bytes.size()));
      out.extent = Box3i::from_size(v.dims);
      out.description = std::string("NumPy .npy, ") + dtype_name(v.dtype);
      break;
    }
    case WorldFormat::kVfw: {
      WorldFileReadOptions wo;
      wo.memory_limit_bytes = limit;
      WorldFile f = read_world_file(path, wo);
      const Grid<std::uint8_t>& g = f.world.voxels;
      out.extent = g.bounds() ? *g.bounds() : g.content_bounds();
      out.description = "voxfield world, format " + std::to_string(f.version) + ", " +
                        std::to_string(f.fields.size()) + " distance field(s)";
      if (options.chunk_edge != 0 && g.chunk_edge() != options.chunk_edge) {
        // Re-chunked chunk by chunk (the saved fields keep the edge they were saved with, so they
        // are dropped: they would no longer match the world's chunks).
        out.world = rechunk_world(f.world, options.chunk_edge, g.bounds(), path.string(), limit);
      } else {
        out.world = std::move(f.world);
        out.fields = std::move(f.fields);
      }
      break;
    }
    case WorldFormat::kVdb: {
      VdbReadOptions vo;
      vo.memory_limit_bytes = limit;
      const VdbFile file = read_vdb(path, vo);
      // The decoded file is held while the world is built from it.
      VdbWorld w = world_from_vdb(file, path.string(), edge,
                                  remaining_memory(limit, file.memory_bytes()), options.vdb_grid);
      out.world = std::move(w.world);
      out.extent = w.extent;
      out.description = std::move(w.description);
      break;
    }
  }
  out.extent = out.extent.unite(out.world.voxels.content_bounds());
  return out;
}

World rechunk_world(const World& world, int chunk_edge, std::optional<Box3i> bounds,
                    const std::string& who, std::uint64_t memory_limit_bytes) {
  const Grid<std::uint8_t>& g = world.voxels;
  World out(chunk_edge, bounds);  // checks the edge and the bounds
  const std::uint64_t limit = effective_memory_limit(memory_limit_bytes);
  const std::uint64_t per_chunk =
      static_cast<std::uint64_t>(chunk_edge) * chunk_edge * chunk_edge + 96;
  const int shift = out.voxels.chunk_shift();
  std::unordered_set<Vec3i, Vec3iHash> dense;
  for (const Vec3i c : g.chunk_coords()) {
    const ChunkView<std::uint8_t> v = g.chunk_view(c);
    Box3i box = g.bounds() ? v.box.intersect(*g.bounds()) : v.box;
    if (bounds) box = box.intersect(*bounds);
    if (box.empty()) continue;
    const Vec3i lo = out.voxels.chunk_of(box.begin),
                hi = out.voxels.chunk_of(box.end - Vec3i::splat(1));
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const Box3i target{{x << shift, y << shift, z << shift},
                             {(x + 1) << shift, (y + 1) << shift, (z + 1) << shift}};
          const Box3i kept = bounds ? target.intersect(*bounds) : target;
          if (v.uniform() && box.contains(kept)) continue;  // a uniform fill: no voxel array
          if (dense.insert({x, y, z}).second && dense.size() * per_chunk > limit) {
            require_memory(dense.size() * per_chunk, limit, who,
                           "its world in chunks of " + std::to_string(chunk_edge) +
                               "^3 (at least " + std::to_string(dense.size()) + " dense chunks)");
          }
        }
  }
  out.voxels = g.rechunked(chunk_edge, bounds);
  out.palette = world.palette;
  out.frame = world.frame;
  return out;
}

std::vector<std::uint8_t> encode_world(const World& world, const Box3i& extent,
                                       WorldFormat format) {
  switch (format) {
    case WorldFormat::kVox:
      return encode_vox(world);
    case WorldFormat::kNpy: {
      Box3i box = extent.unite(world.voxels.content_bounds());
      if (box.empty()) box = Box3i::from_size({1, 1, 1});
      require_memory(dense_bytes(box, 2), 0, "npy output",
                     "a dense volume of " + std::to_string(box.volume()) + " voxels");
      return encode_npy(npy_from_world(world, box));
    }
    case WorldFormat::kVfw:
      return encode_world_file(world);
    case WorldFormat::kVdb:
      return encode_vdb_world(world, extent);
  }
  throw InvalidArgument("encode_world: unknown format");
}

void save_world(const World& world, const Box3i& extent, const std::filesystem::path& path) {
  write_file_atomic(path, encode_world(world, extent, world_format_of(path)));
}

std::string frame_left_out(const World& world, const std::filesystem::path& path) {
  const WorldFormat f = world_format_of(path);
  if (world.frame.is_identity() || f == WorldFormat::kVfw || f == WorldFormat::kVdb) return {};
  return path.string() + " keeps no frame; the world's (" + describe(world.frame) +
         ") is left out (.vfw and .vdb keep it)";
}

}  // namespace voxfield
