// voxfield CLI — loading and saving worlds by file extension.
#include <algorithm>
#include <cctype>

#include "cli.h"
#include "voxfield/npy.h"
#include "voxfield/world_file.h"

namespace voxfield::cli {
namespace {

std::string extension(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e;
}

}  // namespace

LoadedWorld load_world(const std::filesystem::path& path, int chunk_edge) {
  const std::string ext = extension(path);
  if (ext == ".vox") {
    VoxImportOptions options;
    options.chunk_edge = chunk_edge;
    VoxImport in = read_vox(path, options);
    LoadedWorld out{std::move(in.world), "vox", {}, {}, std::move(in.info)};
    const VoxFileInfo& info = *out.vox;
    if (info.has_scene_graph) {
      for (const auto& inst : info.instances)
        if (!inst.hidden) out.extent = out.extent.unite(inst.world_box);
    } else if (!info.models.empty()) {
      out.extent = Box3i::from_size(info.models[0].size);
    }
    out.extent = out.extent.unite(out.world.voxels.content_bounds());
    out.description = "MagicaVoxel .vox, version " + std::to_string(info.version);
    return out;
  }
  if (ext == ".npy") {
    const NpyVolume v = read_npy(path);
    LoadedWorld out{world_from_npy(v, path.string(), chunk_edge), "npy", Box3i::from_size(v.dims),
                    std::string("NumPy .npy, ") + dtype_name(v.dtype), std::nullopt};
    return out;
  }
  if (ext == ".vfw") {
    WorldFile f = read_world_file(path);
    const Box3i extent = f.world.voxels.bounds() ? *f.world.voxels.bounds() : f.world.voxels.content_bounds();
    const std::string description = "voxfield world, format " + std::to_string(f.version) + ", " +
                                    std::to_string(f.fields.size()) + " distance field(s)";
    if (f.world.voxels.chunk_edge() != chunk_edge) {
      // Re-chunk to the edge asked for.
      World w(chunk_edge, f.world.voxels.bounds());
      w.palette = f.world.palette;
      const Box3i content = f.world.voxels.content_bounds();
      std::vector<std::uint8_t> dense(static_cast<std::size_t>(content.volume()));
      f.world.voxels.copy_to_dense(content, dense.data());
      w.voxels.copy_from_dense(content, dense.data());
      return {std::move(w), "vfw", extent, description, std::nullopt};
    }
    return {std::move(f.world), "vfw", extent, description, std::nullopt};
  }
  throw InvalidArgument(path.string() + ": unknown file type \"" + ext + "\" (expected .vox, .npy or .vfw)");
}

void save_world(const World& world, const Box3i& extent, const std::filesystem::path& path) {
  const std::string ext = extension(path);
  if (ext == ".vox") {
    write_vox(world, path);
  } else if (ext == ".npy") {
    Box3i box = extent.unite(world.voxels.content_bounds());
    if (box.empty()) box = Box3i::from_size({1, 1, 1});
    write_npy(npy_from_world(world, box), path);
  } else if (ext == ".vfw") {
    write_world_file(world, path);
  } else {
    throw InvalidArgument(path.string() + ": unknown output type \"" + ext + "\" (expected .vox, .npy or .vfw)");
  }
}

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace voxfield::cli
