// voxfield — reading one OpenVDB tree (Museth, "VDB: High-resolution sparse volumes with dynamic
// topology", ACM TOG 2013) as OpenVDB's file formats 222 to 225 lay it out: the topology first
// (the root's background, tiles and children; each internal node's child and value masks and its
// values; each leaf's value mask), then every leaf's values, depth first with the root's children
// in coordinate order. Values go through OpenVDB's "active mask" compression (a node may store
// only its active values plus up to two inactive ones and a mask choosing between them) and are
// zip or Blosc compressed per node. Every count is checked against the bytes left, every
// decompressed size against what the node needs, and what the tree holds against the memory
// limit, so no input can make the reader read out of bounds or allocate without bound. A clipped
// read (an MPI rank's slab) drops the nodes outside the clip: their values are stepped over by
// their stored sizes, never decompressed.
#include "vdb_read_tree.h"

#include <blosc.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "voxfield/limits.h"

namespace voxfield::detail {
namespace {

// Per-node indicator of what is stored to rebuild inactive values (OpenVDB io/Compression.h).
enum : std::uint8_t {
  kNoMaskOrInactiveVals = 0,  // inactive values are +background
  kNoMaskAndMinusBg = 1,      // inactive values are -background
  kNoMaskAndOneInactiveVal = 2,
  kMaskAndNoInactiveVals = 3,  // a mask selects between -background and +background
  kMaskAndOneInactiveVal = 4,
  kMaskAndTwoInactiveVals = 5,
  kNoMaskAndAllVals = 6,  // every value stored
};

using Value = std::array<double, 3>;

float half_to_float(std::uint16_t h) {
  const std::uint32_t sign = (h >> 15) & 1u, exponent = (h >> 10) & 0x1fu, mantissa = h & 0x3ffu;
  float magnitude;
  if (exponent == 0)
    magnitude = std::ldexp(static_cast<float>(mantissa), -24);  // zero or subnormal
  else if (exponent == 31)
    magnitude = mantissa == 0 ? INFINITY : NAN;
  else
    magnitude = std::ldexp(static_cast<float>(mantissa | 0x400u), static_cast<int>(exponent) - 25);
  return sign ? -magnitude : magnitude;
}

class TreeReader {
 public:
  TreeReader(ByteReader& r, VdbGrid& grid, const VdbTreeReading& how)
      : r_(r), grid_(grid), how_(how) {
    grid_.clip = how.clip;
    full_bytes_ = component_bytes(false) * grid.components;
    stored_bytes_ = component_bytes(grid.half_float) * grid.components;
    full_decode_ = decoder(false);
    stored_decode_ = decoder(grid.half_float);
  }

  void read() {
    if (r_.i32("tree buffer count") != 1) r_.fail("a tree with other than one buffer");
    grid_.background = read_full_value("background value");
    const std::uint32_t tiles = r_.u32("root tile count");
    const std::uint32_t children = r_.u32("root child count");
    const int shift = subtree_shift(0);
    const std::int64_t edge = std::int64_t{1} << shift;
    // A root tile is 12 bytes of origin, a value and an active flag; a child at least its masks.
    if (tiles > r_.remaining() / (13 + full_bytes_)) r_.fail("more root tiles than bytes left");
    std::vector<std::array<std::int32_t, 3>> origins;  // the root's table: one entry per origin
    for (std::uint32_t t = 0; t < tiles; ++t) {
      const Vec3i origin = read_origin(edge, "root tile");
      origins.push_back({origin.x, origin.y, origin.z});
      const Value v = read_full_value("root tile value");
      const std::uint8_t active = r_.u8("root tile active flag");
      if (active > 1) r_.fail("a root tile's active flag is neither 0 nor 1");
      add_tile(origin, shift, v, active != 0);
    }
    if (children > r_.remaining() / 12) r_.fail("more root children than bytes left");
    struct Child {
      Vec3i origin;
      std::vector<PendingLeaf> leaves;
    };
    std::vector<Child> root_children;
    for (std::uint32_t c = 0; c < children; ++c) {
      Child child{read_origin(edge, "root child"), {}};
      origins.push_back({child.origin.x, child.origin.y, child.origin.z});
      read_internal_topology(child.origin, 0, child.leaves);
      root_children.push_back(std::move(child));
    }
    // OpenVDB keeps the root's children in a map ordered by (x, y, z) and writes their buffers
    // in that order, whatever order the topology listed them in.
    std::sort(root_children.begin(), root_children.end(), [](const Child& a, const Child& b) {
      return std::tie(a.origin.x, a.origin.y, a.origin.z) <
             std::tie(b.origin.x, b.origin.y, b.origin.z);
    });
    // OpenVDB's table keeps one entry per origin (and then never reads a shadowed child's
    // buffers): refused rather than guessed.
    std::sort(origins.begin(), origins.end());
    if (std::adjacent_find(origins.begin(), origins.end()) != origins.end())
      r_.fail("two root tiles or children at the same origin");
    std::size_t leaf_count = 0;
    for (const Child& child : root_children)
      for (const PendingLeaf& leaf : child.leaves) leaf_count += leaf.dropped ? 0 : 1;
    // Every leaf's values were counted with its topology: held once, without regrowth.
    grid_.leaves.reserve(grid_.leaves.size() + leaf_count);
    const std::size_t values = leaf_count * (std::size_t{1} << (3 * grid_.log2_dims.back())) *
                               static_cast<std::size_t>(grid_.components);
    grid_.with_leaf_values([values](auto& held) { held.reserve(held.size() + values); });
    for (Child& child : root_children)
      for (PendingLeaf& leaf : child.leaves) read_leaf_buffers(leaf);
  }

 private:
  struct PendingLeaf {
    Vec3i origin;
    std::vector<std::uint64_t> mask;
    bool dropped = false;  // outside the clip: its values are skipped
  };

  // Whether a node's box lies wholly outside the clip (dropped); its stored box is then counted,
  // and all of it as active for an active tile.
  bool drop(const Box3i& box, bool active) {
    if (!how_.clip || !box.intersect(*how_.clip).empty()) return false;
    grid_.dropped_stored = grid_.dropped_stored.unite(box);
    if (active) grid_.dropped_active = grid_.dropped_active.unite(box);
    return true;
  }
  // A dropped leaf's active voxels, from the mask a whole read keeps for it.
  void drop_active(Vec3i origin, const std::vector<std::uint64_t>& mask) {
    const int dim = grid_.log2_dims.back();
    const std::size_t count = std::size_t{1} << (3 * dim);
    for (std::size_t i = 0; i < count; ++i)
      if (bit(mask, i)) {
        const Vec3i p = origin + Vec3i{static_cast<int>(i >> (2 * dim)),
                                       static_cast<int>((i >> dim) & ((1u << dim) - 1)),
                                       static_cast<int>(i & ((1u << dim) - 1))};
        grid_.dropped_active = grid_.dropped_active.unite(Box3i{p, p + Vec3i::splat(1)});
      }
  }

  std::size_t component_bytes(bool half) const {
    switch (grid_.value_type) {
      case VdbValueType::kFloat:
      case VdbValueType::kVec3f:
        return half ? 2 : 4;
      case VdbValueType::kDouble:
        return half ? 2 : 8;
      case VdbValueType::kBool:
        return 1;
      case VdbValueType::kInt32:
        return 4;
    }
    return 4;
  }

  // log2 of the edge, in voxels, of a node at `level` (0: a child of the root).
  int subtree_shift(std::size_t level) const {
    int s = 0;
    for (std::size_t l = level; l < grid_.log2_dims.size(); ++l) s += grid_.log2_dims[l];
    return s;
  }

  Vec3i read_origin(std::int64_t edge, const char* what) {
    const std::uint64_t at = r_.offset();
    Vec3i o;
    o.x = r_.i32("origin");
    o.y = r_.i32("origin");
    o.z = r_.i32("origin");
    for (std::int32_t c : {o.x, o.y, o.z}) {
      if (c % edge != 0)
        r_.fail_at(at, std::string(what) + " origin not aligned to its " + std::to_string(edge) +
                           "-voxel node");
      if (!coord_in_range(c) || !bound_in_range(std::int64_t{c} + edge))
        r_.fail_at(at, std::string(what) + " outside voxfield's coordinate range (|c| < 2^29)");
    }
    return o;
  }

  void charge(std::uint64_t bytes, const char* what) {
    *how_.used_bytes = add_sat(*how_.used_bytes, bytes);
    if (*how_.used_bytes > effective_memory_limit(how_.memory_limit_bytes))
      require_memory(*how_.used_bytes, how_.memory_limit_bytes, r_.name(), what);
  }

  // One decoder per stored layout, chosen once per tree (a node holds up to 2^21 values).
  using Decoder = Value (*)(const std::uint8_t*);
  template <typename T, int N>
  static Value decode_as(const std::uint8_t* p) {
    Value v{};
    for (int c = 0; c < N; ++c) {
      T x;
      std::memcpy(&x, p + c * static_cast<int>(sizeof(T)), sizeof(T));
      if constexpr (std::is_same_v<T, std::uint16_t>)
        v[c] = half_to_float(x);
      else if constexpr (std::is_same_v<T, std::uint8_t>)
        v[c] = x != 0 ? 1 : 0;
      else
        v[c] = static_cast<double>(x);
    }
    return v;
  }
  Decoder decoder(bool half) const {
    switch (grid_.value_type) {
      case VdbValueType::kFloat:
        return half ? &decode_as<std::uint16_t, 1> : &decode_as<float, 1>;
      case VdbValueType::kVec3f:
        return half ? &decode_as<std::uint16_t, 3> : &decode_as<float, 3>;
      case VdbValueType::kDouble:
        return half ? &decode_as<std::uint16_t, 1> : &decode_as<double, 1>;
      case VdbValueType::kBool:
        return &decode_as<std::uint8_t, 1>;  // any non-zero byte is true, as a C++ bool
      case VdbValueType::kInt32:
        return &decode_as<std::int32_t, 1>;
    }
    return &decode_as<float, 1>;
  }
  Value decode(const std::uint8_t* p, bool half) const {
    return (half ? stored_decode_ : full_decode_)(p);
  }

  Value read_full_value(const char* what) {
    return decode(r_.take(full_bytes_, what).data(), false);
  }

  Value negative(const Value& v) const {
    if (grid_.value_type == VdbValueType::kBool) return {v[0] != 0 ? 0.0 : 1.0, 0, 0};
    return {-v[0], -v[1], -v[2]};
  }

  std::vector<std::uint64_t> read_mask(int log2_dim, const char* what) {
    const std::size_t bits = std::size_t{1} << (3 * log2_dim);
    std::vector<std::uint64_t> words((bits + 63) / 64, 0);
    const auto bytes = r_.take(bits / 8, what);
    std::memcpy(words.data(), bytes.data(), bytes.size());
    return words;
  }
  static bool bit(const std::vector<std::uint64_t>& m, std::size_t i) {
    return (m[i >> 6] >> (i & 63)) & 1u;
  }
  static std::size_t count_on(const std::vector<std::uint64_t>& m) {
    std::size_t n = 0;
    for (std::uint64_t w : m) n += static_cast<std::size_t>(std::popcount(w));
    return n;
  }

  // `count` values stored as readData writes them: raw, or a zip / Blosc block led by its
  // 64-bit size (negative: stored raw). Returns their bytes, `count` * stored size; nothing when
  // not `kept` (the values are stepped over, never decompressed).
  std::vector<std::uint8_t> read_data(std::size_t count, bool kept) {
    const std::size_t need = count * stored_bytes_;
    std::vector<std::uint8_t> out;
    if (!(how_.compression & (kVdbCompressZip | kVdbCompressBlosc))) {
      const auto raw = r_.take(need, "node values");
      if (kept) out.assign(raw.begin(), raw.end());
      return out;
    }
    const std::uint64_t at = r_.offset();
    const std::int64_t size = r_.i64("compressed block size");
    if (size <= 0) {
      if (static_cast<std::uint64_t>(-(size + 1)) + 1 != need)
        r_.fail_at(at, "an uncompressed block of " +
                           std::to_string(static_cast<std::uint64_t>(-(size + 1)) + 1) +
                           " bytes where the node holds " + std::to_string(need));
      const auto raw = r_.take(need, "node values");
      if (kept) out.assign(raw.begin(), raw.end());
      return out;
    }
    const auto packed =
        r_.take(static_cast<std::size_t>(std::min<std::uint64_t>(size, r_.remaining() + 1)),
                "compressed node values");
    if (!kept) return out;
    out.resize(need);
    if (how_.compression & kVdbCompressBlosc) {
      std::size_t declared = 0;
      if (blosc_cbuffer_validate(packed.data(), packed.size(), &declared) < 0 || declared != need)
        r_.fail_at(
            at, "a Blosc block that does not hold the node's " + std::to_string(need) + " bytes");
      if (need > 0 &&
          blosc_decompress_ctx(packed.data(), out.data(), need, 1) != static_cast<int>(need))
        r_.fail_at(at, "a Blosc block that does not decompress");
    } else {
      uLongf got = static_cast<uLongf>(need);
      const int status = uncompress(out.data(), &got, packed.data(), packed.size());
      if (status != Z_OK || got != need)
        r_.fail_at(at, "a zip block that does not decompress to the node's " +
                           std::to_string(need) + " bytes");
    }
    return out;
  }

  // OpenVDB's readCompressedValues: `count` values of a node whose value mask is `active`, into
  // `values` (one buffer per tree level, reused from node to node: a top node holds 32768);
  // stepped over when not `kept`.
  void read_values(std::size_t count, const std::vector<std::uint64_t>& active, int log2_dim,
                   std::vector<Value>& values, bool kept = true) {
    std::uint8_t flag = kNoMaskAndAllVals;
    const std::uint64_t at = r_.offset();
    if (how_.format_version >= 222) flag = r_.u8("node compression flag");
    if (flag > kNoMaskAndAllVals)
      r_.fail_at(at, "node compression flag " + std::to_string(flag) + " (expected 0 to 6)");
    const Value bg = grid_.background;
    Value inactive1 = bg;
    Value inactive0 = flag == kNoMaskOrInactiveVals ? bg : negative(bg);
    if (flag == kNoMaskAndOneInactiveVal || flag == kMaskAndOneInactiveVal ||
        flag == kMaskAndTwoInactiveVals) {
      inactive0 = read_full_value("inactive value");
      if (flag == kMaskAndTwoInactiveVals) inactive1 = read_full_value("inactive value");
    }
    std::vector<std::uint64_t> selection((count + 63) / 64, 0);
    if (flag == kMaskAndNoInactiveVals || flag == kMaskAndOneInactiveVal ||
        flag == kMaskAndTwoInactiveVals)
      selection = read_mask(log2_dim, "selection mask");
    const bool mask_compressed =
        (how_.compression & kVdbCompressActiveMask) && flag != kNoMaskAndAllVals;
    const std::size_t stored = mask_compressed ? count_on(active) : count;
    // Half floats with nothing to store store nothing, not even a block size (HalfReader).
    const bool real =
        grid_.value_type != VdbValueType::kBool && grid_.value_type != VdbValueType::kInt32;
    const std::vector<std::uint8_t> bytes = grid_.half_float && real && stored == 0
                                                ? std::vector<std::uint8_t>{}
                                                : read_data(stored, kept);
    if (!kept) return;
    values.resize(count);
    if (stored == count) {
      for (std::size_t i = 0; i < count; ++i)
        values[i] = decode(bytes.data() + i * stored_bytes_, grid_.half_float);
      return;
    }
    for (std::size_t i = 0, j = 0; i < count; ++i) {
      if (bit(active, i))
        values[i] = decode(bytes.data() + (j++) * stored_bytes_, grid_.half_float);
      else
        values[i] = bit(selection, i) ? inactive1 : inactive0;
    }
  }

  void add_tile(Vec3i origin, int shift, const Value& v, bool active) {
    if (!active && v == grid_.background) return;
    if (drop(Box3i{origin, origin + Vec3i::splat(1 << shift)}, active)) return;
    charge(sizeof(VdbTile), "its tiles");
    grid_.tiles.push_back({origin, std::int32_t{1} << shift, active, v});
  }

  // An internal node at `level` (0: a child of the root) with its subtree's topology.
  void read_internal_topology(Vec3i origin, std::size_t level, std::vector<PendingLeaf>& leaves) {
    const int dim = grid_.log2_dims[level];
    const std::size_t count = std::size_t{1} << (3 * dim);
    const int child_shift = subtree_shift(level + 1);
    const auto child_mask = read_mask(dim, "child mask");
    const auto value_mask = read_mask(dim, "value mask");
    charge(count * sizeof(Value), "a node's values");  // held while its children are read
    std::vector<Value>& values = level_values_[level];
    read_values(count, value_mask, dim, values);
    const bool children_are_leaves = level + 2 == grid_.log2_dims.size();
    for (std::size_t i = 0; i < count; ++i) {
      if (!bit(child_mask, i) && !bit(value_mask, i) && values[i] == grid_.background) continue;
      const Vec3i at =
          origin + Vec3i{static_cast<int>(i >> (2 * dim)) << child_shift,
                         static_cast<int>((i >> dim) & ((1u << dim) - 1)) << child_shift,
                         static_cast<int>(i & ((1u << dim) - 1)) << child_shift};
      if (!bit(child_mask, i)) {
        add_tile(at, child_shift, values[i], bit(value_mask, i));
      } else if (children_are_leaves) {
        PendingLeaf leaf{at, read_mask(grid_.log2_dims.back(), "leaf value mask")};
        leaf.dropped = drop(Box3i{at, at + Vec3i::splat(grid_.leaf_edge)}, false);
        // A dropped leaf holds only its mask until its values are stepped over.
        charge(leaf.dropped
                   ? sizeof(PendingLeaf) + leaf.mask.size() * sizeof(std::uint64_t)
                   : sizeof(VdbLeaf) + (grid_.leaf_value_bytes() << (3 * grid_.log2_dims.back())) *
                                           static_cast<std::size_t>(grid_.components),
               "its leaves");
        leaves.push_back(std::move(leaf));
      } else {
        read_internal_topology(at, level + 1, leaves);
      }
    }
    *how_.used_bytes -= count * sizeof(Value);
  }

  void read_leaf_buffers(PendingLeaf& leaf) {
    const int dim = grid_.log2_dims.back();
    const std::size_t count = std::size_t{1} << (3 * dim);
    const std::size_t comps = static_cast<std::size_t>(grid_.components);
    if (leaf.dropped) {
      if (grid_.value_type == VdbValueType::kBool) {
        // (A whole read keeps this copy of the mask for a bool leaf: so do its bounds.)
        leaf.mask = read_mask(dim, "leaf value mask");
        r_.skip(12 + count / 8, "bool leaf origin and values");
      } else {
        r_.skip(count / 8, "leaf value mask");
        read_values(count, leaf.mask, dim, level_values_.back(), /*kept=*/false);
      }
      drop_active(leaf.origin, leaf.mask);
      return;
    }
    std::size_t first = 0;
    grid_.with_leaf_values([&](auto& held) {
      first = held.size();
      held.resize(first + count * comps);
      auto* out = held.data() + first;
      if (grid_.value_type == VdbValueType::kBool) {
        // Bool leaves: their value mask again (OpenVDB keeps this copy), the origin, then one
        // bit per voxel, never compressed.
        leaf.mask = read_mask(dim, "leaf value mask");
        r_.skip(12, "bool leaf origin");
        const auto bits = read_mask(dim, "bool leaf values");
        for (std::size_t i = 0; i < count; ++i) out[i] = bit(bits, i) ? 1 : 0;
      } else {
        // A file's reader uses the topology's mask and seeks over this copy (io::File).
        r_.skip(count / 8, "leaf value mask");
        std::vector<Value>& values = level_values_.back();
        read_values(count, leaf.mask, dim, values);
        // (A float grid's values were decoded from floats or halves: narrowing them back is
        // exact.)
        store(values, count, comps, out);
      }
    });
    grid_.leaves.push_back({leaf.origin, first, std::move(leaf.mask)});
  }

  template <class T>
  static void store(const std::vector<Value>& values, std::size_t count, std::size_t comps,
                    T* out) {
    for (std::size_t i = 0; i < count; ++i)
      for (std::size_t c = 0; c < comps; ++c) out[i * comps + c] = static_cast<T>(values[i][c]);
  }

  ByteReader& r_;
  VdbGrid& grid_;
  const VdbTreeReading& how_;
  std::size_t full_bytes_ = 4, stored_bytes_ = 4;
  Decoder full_decode_ = nullptr, stored_decode_ = nullptr;
  std::array<std::vector<Value>, 5> level_values_;  // internal levels from 0; leaves last
};

}  // namespace

void read_vdb_tree(ByteReader& r, VdbGrid& grid, const VdbTreeReading& how) {
  TreeReader(r, grid, how).read();
}

}  // namespace voxfield::detail
