// voxfield CSG — the octree of a model (Palecek, "A Better Approach to SDF Decomposition": clip
// incrementally down an octree rather than re-clip the whole tree per cell): each child clips its
// parent's pruned tape, empty and full cells stop early, surface cells split down to the depth,
// and the pruned tapes of the leaves are grouped into variants by structure.
#include <chrono>
#include <cmath>
#include <unordered_map>

#include "voxfield/csg_compile.h"

namespace voxfield::csg {
namespace {

class OctreeBuilder {
 public:
  OctreeBuilder(Octree& tree, const OctreeOptions& o)
      : tree_(tree), o_(o), progress_(o.interrupter, "CSG octree", 8) {}

  void run(const Tape& whole) {
    tree_.children.push_back(0);  // the root's slot
    visit(whole, tree_.root, 0, 0, true);
    progress_.throw_if_cancelled();
  }

 private:
  // Fills slot `slot` of tree_.children with the cell's node or leaf.
  void visit(const Tape& parent, const Bounds& box, int level, std::size_t slot, bool top) {
    if (!progress_.keep_going()) return;
    ++tree_.stats.cells_visited;
    Clipped c = clip(parent, box, o_.max_distance);
    if (c.state != CellState::kSurface || level == o_.depth) {
      OctreeLeaf leaf;
      leaf.box = box;
      leaf.level = level;
      leaf.state = c.state;
      leaf.lo = c.lo;
      leaf.hi = c.hi;
      if (c.state == CellState::kSurface) {
        std::string key = structure_key(c.tape);
        auto it = variant_of_.find(key);
        if (it == variant_of_.end()) {
          it = variant_of_.emplace(key, static_cast<int>(tree_.variants.size())).first;
          tree_.variants.push_back({std::move(key), static_cast<int>(tree_.tapes.size()), 0,
                                    static_cast<std::int64_t>(c.tape.code.size())});
        }
        leaf.variant = it->second;
        leaf.tape = static_cast<int>(tree_.tapes.size());
        ++tree_.variants[static_cast<std::size_t>(it->second)].cells;
        tree_.tapes.push_back(std::move(c.tape));
      }
      tree_.children[slot] = -static_cast<std::int32_t>(tree_.leaves.size()) - 1;
      tree_.leaves.push_back(leaf);
      return;
    }
    const std::size_t first = tree_.children.size();
    tree_.children[slot] = static_cast<std::int32_t>(first);
    tree_.children.resize(first + 8, 0);
    const Vec3d mid = (box.lo + box.hi) * 0.5;
    for (int octant = 0; octant < 8; ++octant) {
      Bounds child = box;
      for (int a = 0; a < 3; ++a) {
        if (octant >> a & 1)
          child.lo[a] = mid[a];
        else
          child.hi[a] = mid[a];
      }
      visit(c.tape, child, level + 1, first + static_cast<std::size_t>(octant), false);
      if (top) progress_.advance();
    }
  }

  Octree& tree_;
  const OctreeOptions& o_;
  Progress progress_;
  std::unordered_map<std::string, int> variant_of_;
};

}  // namespace

Octree build_octree(const Tape& tape, const Model& model, const OctreeOptions& options) {
  if (options.depth < 0 || options.depth > 8)
    throw InvalidArgument("octree depth must be 0..8, got " + std::to_string(options.depth));
  const auto start = std::chrono::steady_clock::now();
  Octree tree;
  tree.depth = options.depth;
  if (options.box) {
    if (options.box->empty() ||
        !std::isfinite(options.box->lo.x + options.box->lo.y + options.box->lo.z +
                       options.box->hi.x + options.box->hi.y + options.box->hi.z))
      throw InvalidArgument("the octree's box must be finite with lo <= hi");
    tree.root = *options.box;
  } else {
    const auto bounds = model_bounds(model);
    if (!bounds)
      throw InvalidArgument(
          model.name +
          ": the model is unbounded (it has a plane or a difference from one); give a box");
    // A cube around the bounds, a little larger so that no surface lies on its faces.
    const Vec3d centre = (bounds->lo + bounds->hi) * 0.5, size = bounds->hi - bounds->lo;
    const double edge = std::max({size.x, size.y, size.z, 1e-9}) * (1 + 1e-6);
    tree.root = {centre - Vec3d{1, 1, 1} * (edge / 2), centre + Vec3d{1, 1, 1} * (edge / 2)};
  }
  OctreeBuilder(tree, options).run(tape);
  CompileStats& s = tree.stats;
  s.leaves = static_cast<std::int64_t>(tree.leaves.size());
  std::int64_t nodes = 0;
  for (const OctreeLeaf& l : tree.leaves) {
    s.empty += l.state == CellState::kEmpty;
    s.full += l.state == CellState::kFull;
    if (l.state != CellState::kSurface) continue;
    ++s.surface;
    const auto n =
        static_cast<std::int64_t>(tree.tapes[static_cast<std::size_t>(l.tape)].code.size());
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

double Octree::evaluate(const Tape& whole, Vec3d p) const {
  const auto leaf = leaf_at(p);
  if (!leaf) return csg::evaluate(whole, p);
  const OctreeLeaf& l = leaves[static_cast<std::size_t>(*leaf)];
  switch (l.state) {
    case CellState::kEmpty:
      return l.lo;
    case CellState::kFull:
      return l.hi;
    default:
      return csg::evaluate(tapes[static_cast<std::size_t>(l.tape)], p);
  }
}

}  // namespace voxfield::csg
