// voxfield CSG — the octree of a model (Palecek, "A Better Approach to SDF Decomposition": clip
// incrementally down an octree rather than re-clip the whole tree per cell): each child clips its
// parent's pruned tape, empty and full cells stop early, surface cells split down to the depth,
// and the pruned tapes of the leaves are grouped into variants by structure. The top two levels
// are split serially; the 64 subtrees below them are built in parallel and joined in order, so
// the result does not depend on the thread count.
#include <atomic>
#include <chrono>
#include <cmath>
#include <unordered_map>

#include "csg/tape_internal.h"
#include "voxfield/csg_compile.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield::csg {
namespace {

constexpr int kParallelLevel = 2;

// A subtree as built by one task: child links (entry 0 is the subtree's own root entry), leaves
// and their constants, with variants still local (found by structure hash, confirmed exactly).
struct Part {
  std::vector<std::int32_t> children{0};
  std::vector<OctreeLeaf> leaves;
  std::vector<std::uint32_t> sources;
  std::vector<Tape> variant_tapes;
  std::unordered_map<std::uint64_t, std::vector<int>> variants_by_hash;
  std::int64_t visited = 0;
};

// A cell being visited: its box and index at its level.
struct Cell {
  Bounds box;
  int level = 0;
  std::uint16_t x = 0, y = 0, z = 0;
  Cell child(int octant) const {
    Cell c{box, level + 1, static_cast<std::uint16_t>(x * 2 + (octant & 1)),
           static_cast<std::uint16_t>(y * 2 + (octant >> 1 & 1)),
           static_cast<std::uint16_t>(z * 2 + (octant >> 2 & 1))};
    const Vec3d mid = (box.lo + box.hi) * 0.5;
    for (int a = 0; a < 3; ++a) (octant >> a & 1 ? c.box.lo[a] : c.box.hi[a]) = mid[a];
    return c;
  }
};

// The variant of a tape among those in `tapes`, adding it when new.
int variant_of(std::vector<Tape>& tapes,
               std::unordered_map<std::uint64_t, std::vector<int>>& by_hash, const Tape& t) {
  std::vector<int>& candidates = by_hash[structure_hash(t)];
  for (int v : candidates)
    if (same_structure(tapes[static_cast<std::size_t>(v)], t)) return v;
  tapes.push_back(t);
  candidates.push_back(static_cast<int>(tapes.size() - 1));
  return static_cast<int>(tapes.size() - 1);
}

class Builder {
 public:
  explicit Builder(const OctreeOptions& o) : o_(o) {}

  // A cell at kParallelLevel, left for a worker thread by the serial top levels.
  struct Task {
    Tape tape;
    Cell cell;
    std::size_t slot;  // in the top part's children
  };

  // Fills slot `slot` of part.children with the cell's node or leaf; `scratch` holds one clip
  // result per level, whose memory is reused from cell to cell. With `tasks` (the serial top
  // levels), a cell at kParallelLevel becomes a task, its parent's tape copied, instead.
  void visit(Part& part, const Tape& parent, const Cell& cell, std::size_t slot,
             std::vector<Clipped>& scratch, Progress* progress, std::vector<Task>* tasks) const {
    if (tasks && cell.level == kParallelLevel) {
      tasks->push_back({parent, cell, slot});
      return;
    }
    if (progress && !progress->keep_going()) return;
    ++part.visited;
    Clipped& c = scratch[static_cast<std::size_t>(cell.level)];
    clip_into(parent, cell.box, o_.max_distance, false, c);
    if (c.state != CellState::kSurface || cell.level == o_.depth) {
      leaf(part, c, cell, slot);
      return;
    }
    const std::size_t first = part.children.size();
    part.children[slot] = static_cast<std::int32_t>(first);
    part.children.resize(first + 8, 0);
    for (int octant = 0; octant < 8; ++octant)
      visit(part, c.tape, cell.child(octant), first + static_cast<std::size_t>(octant), scratch,
            progress, tasks);
  }

 private:
  static void leaf(Part& part, const Clipped& c, const Cell& cell, std::size_t slot) {
    OctreeLeaf leaf;
    leaf.x = cell.x;
    leaf.y = cell.y;
    leaf.z = cell.z;
    leaf.level = static_cast<std::uint8_t>(cell.level);
    leaf.state = c.state;
    leaf.lo = c.lo;
    leaf.hi = c.hi;
    if (c.state == CellState::kSurface) {
      leaf.variant = variant_of(part.variant_tapes, part.variants_by_hash, c.tape);
      leaf.source_offset = static_cast<std::int64_t>(part.sources.size());
      for (const Instr& in : c.tape.code) part.sources.push_back(in.source);
    }
    part.children[slot] = -static_cast<std::int32_t>(part.leaves.size()) - 1;
    part.leaves.push_back(leaf);
  }

  const OctreeOptions& o_;
};

// Appends a part to the tree; returns the entry that stands for its root.
std::int32_t join(Octree& tree, std::vector<Tape>& variant_tapes,
                  std::unordered_map<std::uint64_t, std::vector<int>>& by_hash, Part& part) {
  const auto node_offset =
      static_cast<std::int32_t>(tree.children.size()) - 1;  // local k >= 1 -> k + offset
  const auto leaf_offset = static_cast<std::int32_t>(tree.leaves.size());
  const auto source_offset = static_cast<std::int64_t>(tree.sources.size());
  auto remap = [&](std::int32_t e) { return e >= 0 ? e + node_offset : e - leaf_offset; };
  std::vector<int> variant(part.variant_tapes.size());
  for (std::size_t v = 0; v < part.variant_tapes.size(); ++v)
    variant[v] = variant_of(variant_tapes, by_hash, part.variant_tapes[v]);
  tree.variants.resize(variant_tapes.size());
  for (std::size_t k = 1; k < part.children.size(); ++k)
    tree.children.push_back(remap(part.children[k]));
  for (OctreeLeaf leaf : part.leaves) {
    if (leaf.state == CellState::kSurface) {
      leaf.variant = variant[static_cast<std::size_t>(leaf.variant)];
      leaf.source_offset += source_offset;
      ++tree.variants[static_cast<std::size_t>(leaf.variant)].cells;
    }
    tree.leaves.push_back(leaf);
  }
  tree.sources.insert(tree.sources.end(), part.sources.begin(), part.sources.end());
  tree.stats.cells_visited += part.visited;
  const std::int32_t root = remap(part.children[0]);
  part = Part{};  // its memory is no longer needed
  return root;
}

}  // namespace

Octree build_octree(const Tape& tape, const Model& model, const OctreeOptions& options) {
  if (options.depth < 0 || options.depth > 8)
    throw InvalidArgument("octree depth must be 0..8, got " + std::to_string(options.depth));
  const auto start = std::chrono::steady_clock::now();
  static std::atomic<std::uint64_t> next_id{0};
  Octree tree;
  tree.id = next_id.fetch_add(1) + 1;
  tree.depth = options.depth;
  tree.whole = tape;
  if (options.box) {
    tree.root = box_or_bounds(model, options.box);
  } else {
    const Bounds bounds = box_or_bounds(model, std::nullopt);
    // A cube around the bounds, a little larger so that no surface lies on its faces.
    const Vec3d centre = (bounds.lo + bounds.hi) * 0.5, size = bounds.hi - bounds.lo;
    const double edge = std::max({size.x, size.y, size.z, 1e-9}) * (1 + 1e-6);
    tree.root = {centre - Vec3d{1, 1, 1} * (edge / 2), centre + Vec3d{1, 1, 1} * (edge / 2)};
  }
  const Builder builder(options);
  Part top;
  std::vector<Builder::Task> tasks;
  std::vector<Clipped> top_scratch(static_cast<std::size_t>(options.depth) + 1);
  builder.visit(top, tape, Cell{tree.root}, 0, top_scratch, nullptr, &tasks);
  Progress progress(options.interrupter, "CSG octree", static_cast<std::int64_t>(tasks.size()));
  std::vector<Part> parts(tasks.size());
  parallel_for(tasks.size(), 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      std::vector<Clipped> scratch(static_cast<std::size_t>(options.depth) + 1);
      builder.visit(parts[i], tasks[i].tape, tasks[i].cell, 0, scratch, &progress, nullptr);
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  std::vector<Tape> variant_tapes;
  std::unordered_map<std::uint64_t, std::vector<int>> by_hash;
  // The joined arrays' sizes are known: reserve them once (growing them leaf by leaf copied and
  // page-faulted the whole octree several times over).
  std::size_t leaves = top.leaves.size(), sources = top.sources.size(),
              children = top.children.size();
  for (const Part& p : parts) {
    leaves += p.leaves.size();
    sources += p.sources.size();
    children += p.children.size();
  }
  require_memory(leaves * sizeof(OctreeLeaf) + sources * sizeof(std::uint32_t) +
                     children * sizeof(std::int32_t),
                 options.memory_limit_bytes, model.name,
                 "the octree of depth " + std::to_string(options.depth));
  tree.leaves.reserve(leaves);
  tree.sources.reserve(sources);
  tree.children.reserve(children + 1);
  tree.children.push_back(0);  // the root's entry, set below
  tree.children[0] = join(tree, variant_tapes, by_hash, top);
  // The top part was joined first, with its slots at the same indices: each task's subtree hangs
  // from its slot there.
  for (std::size_t i = 0; i < tasks.size(); ++i)
    tree.children[tasks[i].slot] = join(tree, variant_tapes, by_hash, parts[i]);
  for (std::size_t v = 0; v < variant_tapes.size(); ++v) {
    tree.variants[v].key = structure_key(variant_tapes[v]);
    tree.variants[v].tape = std::move(variant_tapes[v]);
  }
  CompileStats& s = tree.stats;
  s.leaves = static_cast<std::int64_t>(tree.leaves.size());
  std::int64_t nodes = 0;
  for (const OctreeLeaf& l : tree.leaves) {
    s.empty += l.state == CellState::kEmpty;
    s.full += l.state == CellState::kFull;
    if (l.state != CellState::kSurface) continue;
    ++s.surface;
    const auto n = static_cast<std::int64_t>(
        tree.variants[static_cast<std::size_t>(l.variant)].tape.code.size());
    nodes += n;
    s.max_nodes = std::max(s.max_nodes, n);
  }
  s.mean_nodes = s.surface ? static_cast<double>(nodes) / static_cast<double>(s.surface) : 0;
  s.variants = static_cast<std::int64_t>(tree.variants.size());
  s.whole_nodes = static_cast<std::int64_t>(tape.code.size());
  s.octree_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return tree;
}
std::optional<int> Octree::leaf_at(Vec3d p) const {
  for (int a = 0; a < 3; ++a)
    if (!(p[a] >= root.lo[a] && p[a] <= root.hi[a])) return std::nullopt;
  Bounds box = root;
  std::int32_t entry = children[0];
  while (entry >= 0) {
    const Vec3d mid = (box.lo + box.hi) * 0.5;
    int octant = 0;
    for (int a = 0; a < 3; ++a) {
      if (p[a] >= mid[a]) {
        octant |= 1 << a;
        box.lo[a] = mid[a];
      } else {
        box.hi[a] = mid[a];
      }
    }
    entry = children[static_cast<std::size_t>(entry) + static_cast<std::size_t>(octant)];
  }
  return -entry - 1;
}

Bounds Octree::leaf_box(const OctreeLeaf& leaf) const {
  const double cells = static_cast<double>(1 << leaf.level);
  const Vec3d size = (root.hi - root.lo) * (1.0 / cells);
  const Vec3d lo = root.lo + Vec3d{leaf.x * size.x, leaf.y * size.y, leaf.z * size.z};
  return {lo, lo + size};
}

std::vector<double> Octree::leaf_params(const OctreeLeaf& leaf) const {
  const Tape& v = variants[static_cast<std::size_t>(leaf.variant)].tape;
  std::vector<double> out;
  out.reserve(v.params.size());
  for (std::size_t i = 0; i < v.code.size(); ++i) {
    const Instr& from = whole.code[sources[static_cast<std::size_t>(leaf.source_offset) + i]];
    const auto first = whole.params.begin() + from.param;
    out.insert(out.end(), first, first + detail::param_count(v.code[i]));
  }
  return out;
}

Tape Octree::leaf_tape(const OctreeLeaf& leaf) const {
  Tape t = variants[static_cast<std::size_t>(leaf.variant)].tape;
  t.params = leaf_params(leaf);
  return t;
}

namespace {

// A few leaf tapes per thread, direct-mapped by leaf: queries along a mesher's edges or a ray
// stay in a handful of cells.
const Tape& cached_leaf_tape(const Octree& tree, int leaf) {
  struct Entry {
    std::uint64_t id = 0;
    int leaf = -1;
    Tape tape;
  };
  thread_local std::array<Entry, 8> cache;
  Entry& e = cache[static_cast<std::size_t>(leaf) % cache.size()];
  if (e.id != tree.id || e.leaf != leaf) {
    e.tape = tree.leaf_tape(tree.leaves[static_cast<std::size_t>(leaf)]);
    e.id = tree.id;
    e.leaf = leaf;
  }
  return e.tape;
}

}  // namespace

double Octree::evaluate(Vec3d p) const {
  const auto leaf = leaf_at(p);
  if (!leaf) return csg::evaluate(whole, p);
  const OctreeLeaf& l = leaves[static_cast<std::size_t>(*leaf)];
  switch (l.state) {
    case CellState::kEmpty:
      return l.lo;
    case CellState::kFull:
      return l.hi;
    default:
      return csg::evaluate(cached_leaf_tape(*this, *leaf), p);
  }
}

double Octree::exact_value(Vec3d p) const {
  const auto leaf = leaf_at(p);
  if (!leaf || leaves[static_cast<std::size_t>(*leaf)].state != CellState::kSurface)
    return csg::evaluate(whole, p);
  return csg::evaluate(cached_leaf_tape(*this, *leaf), p);
}

}  // namespace voxfield::csg
