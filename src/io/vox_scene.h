// voxfield — the scene of a MagicaVoxel .vox file (internal to the .vox reader, vox_reader.cpp):
// its models, the nodes of its scene graph (format 200's nTRN / nGRP / nSHP chunks), and placing
// them in the world (vox_scene.cpp). Placement walks the graph with a depth, visit and instance
// budget, so that cycles and exponential instancing fail cleanly instead of hanging, and counts
// the world's chunks it will touch against the memory limit before it allocates any.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <utility>
#include <vector>

#include "byte_reader.h"
#include "vox_affine.h"
#include "voxfield/vox.h"

namespace voxfield::detail::vox {

using Dict = std::vector<std::pair<std::string, std::string>>;

inline std::optional<std::string> lookup(const Dict& d, std::string_view key) {
  for (const auto& [k, v] : d)
    if (k == key) return v;
  return std::nullopt;
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

// What a .vox file describes and the reader's account of the memory it holds: the parser
// (vox_reader.cpp) fills the models and the graph as it reads their chunks, then place() puts
// the scene into the world.
class Scene {
 public:
  Scene(std::span<const std::uint8_t> bytes, const std::string& name,
        const VoxImportOptions& options)
      : bytes_(bytes), name_(name), options_(options) {}

  std::vector<ModelData> models;
  std::unordered_map<std::int32_t, Node> nodes;
  std::unordered_map<std::int32_t, bool> hidden_layers;

  // Adds what the reader keeps in memory (`what`, read up to byte `at`) and refuses past the limit.
  void charge(std::uint64_t bytes, std::uint64_t at, const char* what);

  // Places the scene's voxels in `world` and describes its instances in `info`: the graph walked
  // from its root, transform node 0, or without a graph model `options.frame` with voxel v at v.
  void place(World& world, VoxFileInfo& info);

 private:
  struct Placement {
    int model;
    Affine frame;
    std::uint64_t offset;  // of the shape node, for messages
    Box3i box;             // where the model's SIZE box lands
  };

  // Within options_.keep_z (everything when there is none).
  bool in_slab(std::int64_t z) const;
  bool in_slab(const Box3i& box) const;
  void visit(std::int32_t id, const Affine& parent, bool hidden, int depth, std::uint64_t from,
             const std::string& name, VoxFileInfo& info);
  void place_instance(const Node& n, const Affine& xf, bool hidden, const std::string& name,
                      VoxFileInfo& info);
  void check_world_memory(const Grid<std::uint8_t>& g) const;

  std::span<const std::uint8_t> bytes_;
  const std::string& name_;
  const VoxImportOptions& options_;
  std::vector<Placement> placements_;
  std::int64_t placed_voxels_ = 0;
  std::int64_t visits_ = 0;
  std::uint64_t reader_bytes_ = 0;  // what the reader holds besides the world's chunks
};

}  // namespace voxfield::detail::vox
