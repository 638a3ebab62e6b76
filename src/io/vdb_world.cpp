// voxfield — what a .vdb file's grids mean to voxfield: their bounds, their values over a box,
// and the world a file holds (vdb.h says which grid and which voxels become solid). The
// memory a world or a dense box will take is counted before anything is allocated.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_set>

#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/vdb.h"

namespace voxfield {
namespace {

Box3i leaf_box(const VdbGrid& g, const VdbLeaf& leaf) {
  return {leaf.origin, leaf.origin + Vec3i::splat(g.leaf_edge)};
}
Box3i tile_box(const VdbTile& t) {
  return {t.origin, t.origin + Vec3i::splat(t.edge)};
}

// The position of a voxel of `box` in an x-fastest array over it.
struct DenseIndex {
  Box3i box;
  std::size_t operator()(Vec3i p) const {
    const Vec3i d = p - box.begin, size = box.size();
    return (static_cast<std::size_t>(d.z) * static_cast<std::size_t>(size.y) +
            static_cast<std::size_t>(d.y)) *
               static_cast<std::size_t>(size.x) +
           static_cast<std::size_t>(d.x);
  }
};

// f(voxel, index of its first component in the leaf values) for every voxel of a leaf.
template <typename F>
void for_each_leaf_voxel(const VdbGrid& g, const VdbLeaf& leaf, F&& f) {
  const int e = g.leaf_edge;
  std::size_t i = 0;
  for (int x = 0; x < e; ++x)
    for (int y = 0; y < e; ++y)
      for (int z = 0; z < e; ++z, ++i)
        f(leaf.origin + Vec3i{x, y, z}, static_cast<int>(i),
          leaf.first_value + i * static_cast<std::size_t>(g.components));
}

const VdbMetadata* find_meta(const VdbGrid& g, const char* key) {
  const auto it = g.metadata.find(key);
  return it == g.metadata.end() ? nullptr : &it->second;
}

// Which voxels of a grid are solid in the world it makes (vdb.h).
enum class SolidRule { kMaterial, kTrue, kInside, kPositive, kZero, kNonZeroVector };

SolidRule rule_for(const VdbGrid& g) {
  const VdbMetadata* kind = find_meta(g, "voxfield_kind");
  switch (g.value_type) {
    case VdbValueType::kInt32:
      return SolidRule::kMaterial;
    case VdbValueType::kBool:
      return SolidRule::kTrue;
    case VdbValueType::kVec3f:
      return SolidRule::kNonZeroVector;
    case VdbValueType::kFloat:
    case VdbValueType::kDouble:
      break;
  }
  if (g.grid_class == "level set") return SolidRule::kInside;
  if (kind && kind->text == "unsigned distance") return SolidRule::kZero;  // distance to solid
  return SolidRule::kPositive;
}

// The components of the leaf value from index `first` of the grid's leaf values (`values`, as
// VdbGrid::with_leaf_values gives them; components beyond the grid's are 0).
template <class Values>
std::array<double, 3> leaf_components(const VdbGrid& g, const Values& values, std::size_t first) {
  std::array<double, 3> v{};
  for (std::size_t c = 0; c < static_cast<std::size_t>(g.components); ++c) v[c] = values[first + c];
  return v;
}

// The material a value makes under a rule, or -1 for a material outside 0..255.
int material_of(SolidRule rule, const double* v, bool active) {
  switch (rule) {
    case SolidRule::kMaterial:
      if (!active) return 0;
      return v[0] >= 0 && v[0] <= 255 ? static_cast<int>(v[0]) : -1;
    case SolidRule::kTrue:
      return active && v[0] != 0 ? 1 : 0;
    case SolidRule::kInside:
      return v[0] < 0 ? 1 : 0;
    case SolidRule::kPositive:
      return active && v[0] > 0 ? 1 : 0;
    case SolidRule::kZero:
      return v[0] <= 0 ? 1 : 0;
    case SolidRule::kNonZeroVector:
      return active && (v[0] != 0 || v[1] != 0 || v[2] != 0) ? 1 : 0;
  }
  return 0;
}

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

Box3i VdbGrid::stored_bounds() const {
  Box3i b = dropped_stored;
  for (const VdbTile& t : tiles) b = b.unite(tile_box(t));
  for (const VdbLeaf& l : leaves) b = b.unite(leaf_box(*this, l));
  return b;
}

Box3i VdbGrid::active_bounds() const {
  Box3i b = dropped_active;
  for (const VdbTile& t : tiles)
    if (t.active) b = b.unite(tile_box(t));
  for (const VdbLeaf& l : leaves) {
    if (std::all_of(l.active_bits.begin(), l.active_bits.end(),
                    [](std::uint64_t w) { return w == 0; }))
      continue;
    for_each_leaf_voxel(*this, l, [&](Vec3i p, int i, std::size_t) {
      if (leaf_active(l, i)) b = b.unite(Box3i{p, p + Vec3i::splat(1)});
    });
  }
  return b;
}

std::vector<double> VdbGrid::dense(const Box3i& box, std::uint64_t memory_limit_bytes) const {
  const std::uint64_t comps = static_cast<std::uint64_t>(components);
  if (!box.in_range())
    throw InvalidArgument("vdb grid \"" + name + "\": a box outside voxfield's range");
  require_memory(dense_bytes(box, 8 * comps), memory_limit_bytes, "vdb grid \"" + name + "\"",
                 "a dense box of " + std::to_string(box.volume()) + " voxels");
  std::vector<double> out(static_cast<std::size_t>(box.volume() * components));
  if (box.empty()) return out;
  const DenseIndex at{box};
  auto index = [&](Vec3i p) { return at(p) * comps; };
  for (std::size_t i = 0; i < out.size(); i += comps)
    for (std::size_t c = 0; c < comps; ++c) out[i + c] = background[c];
  for (const VdbTile& t : tiles) {
    const Box3i b = tile_box(t).intersect(box);
    for (int z = b.begin.z; z < b.end.z; ++z)
      for (int y = b.begin.y; y < b.end.y; ++y)
        for (int x = b.begin.x; x < b.end.x; ++x)
          for (std::size_t c = 0; c < comps; ++c) out[index({x, y, z}) + c] = t.value[c];
  }
  with_leaf_values([&](const auto& values) {
    for (const VdbLeaf& l : leaves) {
      if (leaf_box(*this, l).intersect(box).empty()) continue;
      for_each_leaf_voxel(*this, l, [&](Vec3i p, int, std::size_t first) {
        if (!box.contains(p)) return;
        for (std::size_t c = 0; c < comps; ++c) out[index(p) + c] = values[first + c];
      });
    }
  });
  return out;
}

std::vector<std::uint8_t> VdbGrid::dense_active(const Box3i& box,
                                                std::uint64_t memory_limit_bytes) const {
  if (!box.in_range())
    throw InvalidArgument("vdb grid \"" + name + "\": a box outside voxfield's range");
  require_memory(dense_bytes(box, 1), memory_limit_bytes, "vdb grid \"" + name + "\"",
                 "an activity mask of " + std::to_string(box.volume()) + " voxels");
  std::vector<std::uint8_t> out(static_cast<std::size_t>(box.volume()), 0);
  if (box.empty()) return out;
  const DenseIndex index{box};
  for (const VdbTile& t : tiles) {
    if (!t.active) continue;
    const Box3i b = tile_box(t).intersect(box);
    for (int z = b.begin.z; z < b.end.z; ++z)
      for (int y = b.begin.y; y < b.end.y; ++y)
        for (int x = b.begin.x; x < b.end.x; ++x) out[index({x, y, z})] = 1;
  }
  for (const VdbLeaf& l : leaves) {
    if (leaf_box(*this, l).intersect(box).empty()) continue;
    for_each_leaf_voxel(*this, l, [&](Vec3i p, int i, std::size_t) {
      if (box.contains(p)) out[index(p)] = leaf_active(l, i) ? 1 : 0;
    });
  }
  return out;
}

namespace {

// The grid a world comes from: the one named `grid_name` when given (else InvalidArgument naming
// the file and listing its grids), else the first of voxfield's kind "world", else the first Int32
// grid, else the first.
const VdbGrid& world_grid(const VdbFile& file, const std::string& name,
                          const std::string& grid_name) {
  if (!grid_name.empty()) {
    std::string names;
    for (const VdbGrid& g : file.grids) {
      if (g.name == grid_name) return g;
      names += std::string(names.empty() ? "" : ", ") + "'" + g.name + "' (" +
               vdb_value_type_name(g.value_type) + ")";
    }
    throw InvalidArgument(name + " has no grid named '" + grid_name + "'; its grids: " + names);
  }
  for (const VdbGrid& g : file.grids) {
    const VdbMetadata* kind = find_meta(g, "voxfield_kind");
    if (kind && kind->text == "world" && g.value_type == VdbValueType::kInt32) return g;
  }
  for (const VdbGrid& g : file.grids)
    if (g.value_type == VdbValueType::kInt32) return g;
  return file.grids.front();
}

}  // namespace

VdbWorld world_from_vdb(const VdbFile& file, const std::string& name, int chunk_edge,
                        std::uint64_t memory_limit_bytes, const std::string& grid_name) {
  if (file.grids.empty())
    throw FormatError(name, 0, "holds no float, double, bool, int32 or vec3s grid");
  const VdbGrid& g = world_grid(file, name, grid_name);
  const SolidRule rule = rule_for(g);

  VdbWorld out;
  out.world = World(chunk_edge);
  Grid<std::uint8_t>& voxels = out.world.voxels;
  const int shift = voxels.chunk_shift();
  const std::uint64_t limit = effective_memory_limit(memory_limit_bytes);
  const std::uint64_t dense_chunk = (std::uint64_t{1} << (3 * shift)) + 96, uniform_chunk = 96;

  // Count what the world will hold before building it: the chunks solid tiles cover, and the
  // chunks solid leaf voxels make dense.
  std::uint64_t need = 0;
  std::unordered_set<Vec3i, Vec3iHash> dense;
  // Every chunk over `box` dense: a leaf's voxels are placed one by one.
  auto count_dense = [&](const Box3i& box) {
    const Vec3i lo = voxels.chunk_of(box.begin), hi = voxels.chunk_of(box.end - Vec3i::splat(1));
    for (int z = lo.z; z <= hi.z && need <= limit; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x)
          if (dense.insert({x, y, z}).second) need = add_sat(need, dense_chunk);
  };
  // The chunks over a tile's `box`: those it covers whole are uniform (a fill stores one value),
  // the others dense. Only the chunk rows that reach the box's faces are walked (a tile may cover
  // millions of chunks).
  auto count_chunks = [&](const Box3i& box) {
    const std::int64_t edge = std::int64_t{1} << shift;
    const Vec3i lo = voxels.chunk_of(box.begin), hi = voxels.chunk_of(box.end - Vec3i::splat(1));
    auto whole_along = [&](int a, std::int64_t c) {  // chunk c of axis a lies in the box
      return c * edge >= box.begin[a] && (c + 1) * edge <= std::int64_t{box.end[a]};
    };
    std::uint64_t whole = 1;
    for (int a = 0; a < 3; ++a) {
      std::uint64_t n = 0;
      for (const std::int64_t c : {std::int64_t{lo[a]}, std::int64_t{hi[a]}})
        n += whole_along(a, c) ? 0 : 1;
      const std::uint64_t span = static_cast<std::uint64_t>(std::int64_t{hi[a]} - lo[a] + 1);
      n = lo[a] == hi[a] ? (whole_along(a, lo[a]) ? 0 : 1) : n;
      whole = mul_sat(whole, span - n);
    }
    need = add_sat(need, mul_sat(whole, uniform_chunk));
    bool aligned = true;  // on the chunk grid (an unclipped tile of a chunk or more): all whole
    for (int a = 0; a < 3; ++a) aligned = aligned && whole_along(a, lo[a]) && whole_along(a, hi[a]);
    if (aligned) return;
    auto visit = [&](int x, int y, int z) {
      if (!(whole_along(0, x) && whole_along(1, y) && whole_along(2, z)) &&
          dense.insert({x, y, z}).second)
        need = add_sat(need, dense_chunk);
    };
    for (int z = lo.z; z <= hi.z && need <= limit; ++z)
      for (int y = lo.y; y <= hi.y && need <= limit; ++y) {
        if (whole_along(1, y) && whole_along(2, z)) {  // a row inside but for its ends
          visit(lo.x, y, z);
          if (hi.x != lo.x) visit(hi.x, y, z);
          continue;
        }
        for (int x = lo.x; x <= hi.x && need <= limit; ++x) visit(x, y, z);
      }
  };
  // What of a node lies in the clip (all of it when the file was read whole).
  auto clipped = [&](const Box3i& box) { return g.clip ? box.intersect(*g.clip) : box; };
  for (const VdbTile& t : g.tiles) {
    if (need > limit) break;
    const Box3i box = clipped(tile_box(t));
    if (box.empty() || material_of(rule, t.value.data(), t.active) == 0) continue;
    count_chunks(box);
  }
  g.with_leaf_values([&](const auto& values) {
    for (const VdbLeaf& l : g.leaves) {
      if (need > limit) break;
      const Box3i box = clipped(leaf_box(g, l));
      bool solid = false;
      for_each_leaf_voxel(g, l, [&](Vec3i p, int i, std::size_t first) {
        solid =
            solid || (box.contains(p) && material_of(rule, leaf_components(g, values, first).data(),
                                                     g.leaf_active(l, i)) != 0);
      });
      if (solid) count_dense(box);
    }
  });
  require_memory(need, limit, name, "its world (grid \"" + g.name + "\")");

  for (const VdbTile& t : g.tiles) {
    const int m = material_of(rule, t.value.data(), t.active);
    if (m < 0)
      throw FormatError(name, 0,
                        "grid \"" + g.name + "\" has material " + format_number(t.value[0]) +
                            " (outside 0..255)");
    const Box3i box = clipped(tile_box(t));
    if (m != 0 && !box.empty()) voxels.fill(box, static_cast<std::uint8_t>(m));
  }
  g.with_leaf_values([&](const auto& values) {
    for (const VdbLeaf& l : g.leaves)
      for_each_leaf_voxel(g, l, [&](Vec3i p, int i, std::size_t first) {
        if (g.clip && !g.clip->contains(p)) return;
        const auto v = leaf_components(g, values, first);
        const int m = material_of(rule, v.data(), g.leaf_active(l, i));
        if (m < 0)
          throw FormatError(name, 0,
                            "grid \"" + g.name + "\" has material " + format_number(v[0]) +
                                " at (" + std::to_string(p.x) + ", " + std::to_string(p.y) + ", " +
                                std::to_string(p.z) + ") (outside 0..255)");
        if (m != 0) voxels.set(p, static_cast<std::uint8_t>(m));
      });
  });
  voxels.compact();

  if (const VdbMetadata* p = find_meta(g, "voxfield_palette"); p && p->text.size() == 256 * 8) {
    Palette pal{};
    bool ok = true;
    for (int i = 0; i < 256 && ok; ++i) {
      std::uint8_t c[4];
      for (int k = 0; k < 4 && ok; ++k) {
        unsigned v = 0;
        ok = std::sscanf(p->text.c_str() + i * 8 + k * 2, "%2x", &v) == 1;
        c[k] = static_cast<std::uint8_t>(v);
      }
      pal[static_cast<std::size_t>(i)] = {c[0], c[1], c[2], c[3]};
    }
    if (ok) out.world.palette = pal;
  }
  const VdbMetadata* lo = find_meta(g, "voxfield_extent_min");
  const VdbMetadata* hi = find_meta(g, "voxfield_extent_max");
  if (lo && hi && lo->numbers.size() == 3 && hi->numbers.size() == 3) {
    // Numbers a file controls: checked finite and in range before any conversion.
    auto in_range = [](double v) {
      return std::isfinite(v) && v >= -kCoordLimit && v < kCoordLimit;
    };
    bool ok = lo->type == "vec3i" && hi->type == "vec3i";
    for (int c = 0; c < 3; ++c) ok = ok && in_range(lo->numbers[c]) && in_range(hi->numbers[c]);
    auto vec = [](const std::vector<double>& n, int add) {
      return Vec3i{static_cast<int>(n[0]) + add, static_cast<int>(n[1]) + add,
                   static_cast<int>(n[2]) + add};
    };
    const Vec3i a = ok ? vec(lo->numbers, 0) : Vec3i{}, b = ok ? vec(hi->numbers, 1) : Vec3i{};
    if (ok && a.x < b.x && a.y < b.y && a.z < b.z) out.extent = Box3i{a, b};
  }
  out.extent = out.extent.unite(voxels.content_bounds());
  out.stored = g.stored_bounds();
  // The frame: the transform takes index (i, j, k) to the voxel's centre, voxel coordinates
  // (i, j, k) + 1/2, so the frame's origin lies half a voxel back along each axis.
  std::array<double, 12> m = g.index_to_world;
  for (int row = 0; row < 3; ++row)
    m[4 * row + 3] -= 0.5 * (m[4 * row] + m[4 * row + 1] + m[4 * row + 2]);
  std::string frame_note;
  try {
    out.world.frame = VoxelFrame::from_matrix(m, name);
  } catch (const InvalidArgument&) {
    frame_note = " (a transform that shears or mirrors: read in the identity frame)";
  }
  out.description = "OpenVDB .vdb, format " + std::to_string(file.format_version) + " (OpenVDB " +
                    std::to_string(file.library_major) + "." + std::to_string(file.library_minor) +
                    "), grid \"" + g.name + "\" " + vdb_value_type_name(g.value_type) +
                    (g.half_float ? " (half)" : "") + ", class " + g.grid_class + ", voxel size " +
                    format_number(g.voxel_size[0]) + " x " + format_number(g.voxel_size[1]) +
                    " x " + format_number(g.voxel_size[2]) + frame_note;
  return out;
}

}  // namespace voxfield
