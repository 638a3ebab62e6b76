// voxfield — placing the scene of a MagicaVoxel .vox file in the world (vox_scene.h): the walk of
// its scene graph (MagicaVoxel's file-format notes, the extension for the scene graph in format
// 200: transforms compose down nTRN chains, groups fan out, shapes place a model) and the memory
// estimate of the world it builds, both checked before anything is allocated.
#include "vox_scene.h"

#include <algorithm>
#include <array>
#include <unordered_set>

#include "voxfield/limits.h"

namespace voxfield::detail::vox {
namespace {

constexpr int kMaxSceneDepth = 64;  // nesting of nTRN/nGRP; real files use < 10
constexpr std::int64_t kMaxInstances = 1 << 20;
constexpr std::int64_t kMaxVisits = 1
                                    << 22;  // node visits: bounds DAGs that instance exponentially
constexpr std::int64_t kMaxPlacedVoxels = std::int64_t{1} << 32;
// What the reader itself keeps per item, for the memory estimate (the world's chunks are
// counted separately): a placed instance (its record and placement), a chunk of the world beyond
// its voxels (hash node and bookkeeping).
constexpr std::uint64_t kBytesPerInstance = 192;
constexpr std::uint64_t kBytesPerChunkNode = 96;

bool is_hidden(const Dict& d) {
  const auto h = lookup(d, "_hidden");
  return h && *h == "1";
}

}  // namespace

void Scene::charge(std::uint64_t bytes, std::uint64_t at, const char* what) {
  reader_bytes_ = add_sat(reader_bytes_, bytes);
  if (reader_bytes_ > effective_memory_limit(options_.memory_limit_bytes)) {
    require_memory(reader_bytes_, options_.memory_limit_bytes, name_,
                   std::string("reading ") + what + " (up to byte " + std::to_string(at) + ")");
  }
}

void Scene::place(World& world, VoxFileInfo& info) {
  ByteReader r(bytes_, name_);
  if (!nodes.empty()) {
    // The root is transform node 0 by convention.
    if (nodes.find(0) == nodes.end()) r.fail_at(8, "scene graph has no root node 0");
    visit(0, Affine{}, false, 0, nodes.at(0).offset, "", info);
  } else if (!models.empty()) {
    if (options_.frame < 0 || static_cast<std::size_t>(options_.frame) >= models.size()) {
      throw InvalidArgument(name_ + ": frame " + std::to_string(options_.frame) +
                            " requested but the file has " + std::to_string(models.size()) +
                            " models");
    }
    // Placed with voxel v at v: the transform that does so for the model's size.
    const ModelData& m = models[static_cast<std::size_t>(options_.frame)];
    Affine identity;
    for (int k = 0; k < 3; ++k) identity.t[k] = m.info.size[k] / 2;
    placements_.push_back({options_.frame, identity, 8, Box3i::from_size(m.info.size)});
  }
  check_world_memory(world.voxels);
  for (const Placement& pl : placements_) {
    if (!in_slab(pl.box)) continue;
    const ModelData& m = models[static_cast<std::size_t>(pl.model)];
    const std::array<std::int64_t, 3> pivot{m.info.size.x / 2, m.info.size.y / 2,
                                            m.info.size.z / 2};
    m.for_each_voxel([&](int x, int y, int z, std::uint8_t c) {
      const auto p = pl.frame.place({x, y, z}, pivot);
      if (in_slab(p[2]))
        world.voxels.set({static_cast<int>(p[0]), static_cast<int>(p[1]), static_cast<int>(p[2])},
                         c);
    });
  }
}

bool Scene::in_slab(std::int64_t z) const {
  return !options_.keep_z || (z >= options_.keep_z->first && z < options_.keep_z->second);
}

bool Scene::in_slab(const Box3i& box) const {
  return !options_.keep_z ||
         (options_.keep_z->first < options_.keep_z->second && box.end.z > options_.keep_z->first &&
          box.begin.z < options_.keep_z->second);
}

// Walks the scene graph depth first; `name` is the _name of the nearest transform above.
void Scene::visit(std::int32_t id, const Affine& parent, bool hidden, int depth, std::uint64_t from,
                  const std::string& name, VoxFileInfo& info) {
  ByteReader r(bytes_, name_);
  if (depth > kMaxSceneDepth) {
    r.fail_at(from, "scene graph nested deeper than " + std::to_string(kMaxSceneDepth) +
                        " levels (a cycle?)");
  }
  if (++visits_ > kMaxVisits) {
    r.fail_at(from, "scene graph walk exceeds " + std::to_string(kMaxVisits) + " node visits");
  }
  auto it = nodes.find(id);
  if (it == nodes.end()) r.fail_at(from, "reference to missing scene node " + std::to_string(id));
  const Node& n = it->second;
  hidden = hidden || is_hidden(n.attributes);
  switch (n.kind) {
    case Node::kTransform: {
      auto layer = hidden_layers.find(n.layer);
      hidden = hidden || (layer != hidden_layers.end() && layer->second);
      visit(n.child, parent.then_child(n.frame0), hidden, depth + 1, n.offset,
            lookup(n.attributes, "_name").value_or(""), info);
      break;
    }
    case Node::kGroup:
      for (std::int32_t child : n.children)
        visit(child, parent, hidden, depth + 1, n.offset, name, info);
      break;
    case Node::kShape:
      place_instance(n, parent, hidden, name, info);
      break;
  }
}

// Records an instance; its voxels are placed by place() once the whole scene's cost is known.
void Scene::place_instance(const Node& n, const Affine& xf, bool hidden, const std::string& name,
                           VoxFileInfo& info) {
  ByteReader r(bytes_, name_);
  if (n.model < 0 || static_cast<std::size_t>(n.model) >= models.size()) {
    r.fail_at(n.offset, "shape references model " + std::to_string(n.model) + " but the file has " +
                            std::to_string(models.size()));
  }
  if (static_cast<std::int64_t>(info.instances.size()) >= kMaxInstances) {
    r.fail_at(n.offset, "more than " + std::to_string(kMaxInstances) + " instances");
  }
  charge(kBytesPerInstance + name.size(), n.offset, "its scene graph's instances");
  const ModelData& m = models[static_cast<std::size_t>(n.model)];
  const std::array<std::int64_t, 3> pivot{m.info.size.x / 2, m.info.size.y / 2, m.info.size.z / 2};
  const auto a = xf.place({0, 0, 0}, pivot);
  const auto b = xf.place({m.info.size.x - 1, m.info.size.y - 1, m.info.size.z - 1}, pivot);
  for (int k = 0; k < 3; ++k) {
    if (!coord_in_range(std::min(a[k], b[k])) || !coord_in_range(std::max(a[k], b[k]))) {
      r.fail_at(n.offset, "instance of model " + std::to_string(n.model) + " spans " +
                              std::to_string(std::min(a[k], b[k])) + ".." +
                              std::to_string(std::max(a[k], b[k])) + " on axis " + "xyz"[k] +
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
  info.instances.push_back(inst);
  if (hidden && !options_.include_hidden) return;
  placed_voxels_ += m.solid_count();
  if (placed_voxels_ > kMaxPlacedVoxels) {
    r.fail_at(n.offset, "scene places more than " + std::to_string(kMaxPlacedVoxels) + " voxels");
  }
  placements_.push_back({n.model, xf, n.offset, info.instances.back().world_box});
}

// The world's chunks every placement touches, counted before any is allocated: while voxels are
// placed each touched chunk is dense (chunk_edge^3 bytes). An instance with fewer voxels than
// chunks in its box adds the chunks of its voxels, others every chunk of the box: an upper bound
// within one instance's box, exact where instances are sparse (the case that costs most).
void Scene::check_world_memory(const Grid<std::uint8_t>& g) const {
  const int shift = g.chunk_shift();
  const std::uint64_t per_chunk = static_cast<std::uint64_t>(g.chunk_volume()) + kBytesPerChunkNode;
  const std::uint64_t limit = effective_memory_limit(options_.memory_limit_bytes);
  const std::uint64_t budget = limit > reader_bytes_ ? limit - reader_bytes_ : 0;
  const std::uint64_t max_chunks = budget / per_chunk;
  std::unordered_set<Vec3i, Vec3iHash> chunks;
  auto add = [&](Vec3i k, std::uint64_t at) {
    if (chunks.insert(k).second && chunks.size() > max_chunks) {
      require_memory(add_sat(reader_bytes_, mul_sat(chunks.size(), per_chunk)), limit, name_,
                     "placing its voxels (at least " + std::to_string(chunks.size()) +
                         " chunks of " + std::to_string(g.chunk_edge()) +
                         "^3 touched, from the instance at byte " + std::to_string(at) + " on)");
    }
  };
  for (const Placement& pl : placements_) {
    if (!in_slab(pl.box)) continue;
    const ModelData& m = models[static_cast<std::size_t>(pl.model)];
    // The box's part within the slab: only its chunks are touched.
    Box3i box = pl.box;
    if (options_.keep_z) {
      box.begin.z = std::max(box.begin.z, options_.keep_z->first);
      box.end.z = std::min(box.end.z, options_.keep_z->second);
    }
    const Vec3i lo = g.chunk_of(box.begin), hi = g.chunk_of(box.end - Vec3i::splat(1));
    const std::int64_t box_chunks =
        std::int64_t{hi.x - lo.x + 1} * (hi.y - lo.y + 1) * (hi.z - lo.z + 1);
    if (m.solid_count() < box_chunks) {
      const std::array<std::int64_t, 3> pivot{m.info.size.x / 2, m.info.size.y / 2,
                                              m.info.size.z / 2};
      m.for_each_voxel([&](int x, int y, int z, std::uint8_t) {
        const auto p = pl.frame.place({x, y, z}, pivot);
        if (!in_slab(p[2])) return;
        add({static_cast<int>(p[0] >> shift), static_cast<int>(p[1] >> shift),
             static_cast<int>(p[2] >> shift)},
            pl.offset);
      });
    } else {
      for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
          for (int x = lo.x; x <= hi.x; ++x) add({x, y, z}, pl.offset);
    }
  }
}

}  // namespace voxfield::detail::vox
