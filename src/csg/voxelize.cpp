// voxfield CSG — voxelisation: a model into a World (solid where its value at the voxel centre is
// <= 0, material from the paints) and optionally into the field of its values. The grid is walked
// as an octree of voxel boxes: each cell clips its parent's pruned tape to the box of its voxel
// centres, cells found empty or full are filled without evaluating (unless exact values are
// wanted there), and leaves evaluate their small tapes in batches.
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>

#include "voxfield/csg_compile.h"
#include "voxfield/limits.h"
#include "voxfield/parallel.h"

namespace voxfield::csg {
namespace {

// Cells of at most this edge (in voxels) are handed to worker threads whole.
constexpr int kJobEdge = 64;

struct Job {
  Box3i box;
  std::shared_ptr<const Tape> tape;  // the parent cell's, shared by its jobs
};

class Voxelizer {
 public:
  Voxelizer(const Voxelized& out, const VoxelizeOptions& o, std::vector<std::uint8_t>& materials,
            float* field)
      : out_(out), o_(o), materials_(materials), field_(field) {}

  // The top of the octree, serially, down to cells of kJobEdge.
  void split(const std::shared_ptr<const Tape>& parent, const Box3i& box, std::vector<Job>& jobs,
             VoxelizeStats& s) {
    if (box.empty()) return;
    const Vec3i size = box.size();
    if (std::max({size.x, size.y, size.z}) <= kJobEdge) {
      jobs.push_back({box, parent});
      return;
    }
    Clipped c = prune(*parent, box, s);
    if (settled(c)) {
      fill(c, box, s);
      return;
    }
    const auto tape = std::make_shared<const Tape>(std::move(c.tape));
    for (const Box3i& child : halves(box)) split(tape, child, jobs, s);
  }

  // A job's cell and everything below it.
  void cell(const Tape& parent, const Box3i& box, VoxelizeStats& s) {
    if (box.empty()) return;
    const Clipped c = prune(parent, box, s);
    if (settled(c)) {
      fill(c, box, s);
      return;
    }
    const Vec3i size = box.size();
    if (std::max({size.x, size.y, size.z}) <= o_.leaf_edge || !o_.prune) {
      leaf(c.tape, box, s);
      return;
    }
    for (const Box3i& child : halves(box)) cell(c.tape, child, s);
  }

 private:
  Clipped prune(const Tape& parent, const Box3i& box, VoxelizeStats& s) const {
    ++s.cells;
    if (!o_.prune) {  // whole-tape evaluation, for comparison: every cell is a leaf
      Clipped c;
      c.tape = parent;
      return c;
    }
    return clip(parent, centres(box), o_.max_distance);
  }

  // Whether a cell needs no evaluation: empty or full, its field (if any) clamped there, its
  // material (if full) one constant.
  bool settled(const Clipped& c) const {
    if (c.state == CellState::kSurface) return false;
    if (o_.field && !(c.lo >= o_.max_distance || c.hi <= -o_.max_distance)) return false;
    return c.state == CellState::kEmpty || c.material >= 0;
  }

  void fill(const Clipped& c, const Box3i& box, VoxelizeStats& s) const {
    (c.state == CellState::kEmpty ? s.empty_cells : s.full_cells)++;
    const std::uint8_t m = c.state == CellState::kEmpty ? 0 : static_cast<std::uint8_t>(c.material);
    const float f =
        static_cast<float>(c.state == CellState::kEmpty ? o_.max_distance : -o_.max_distance);
    for (int z = box.begin.z; z < box.end.z; ++z)
      for (int y = box.begin.y; y < box.end.y; ++y) {
        const std::size_t row = index({box.begin.x, y, z});
        std::fill_n(&materials_[row], box.size().x, m);
        if (field_) std::fill_n(field_ + row, box.size().x, f);
      }
  }

  void leaf(const Tape& tape, const Box3i& box, VoxelizeStats& s) const {
    ++s.surface_cells;
    s.mean_nodes += static_cast<double>(tape.code.size());
    s.max_nodes = std::max(s.max_nodes, static_cast<std::int64_t>(tape.code.size()));
    const Vec3i size = box.size();
    std::vector<Vec3d> points(static_cast<std::size_t>(size.x));
    std::vector<double> values(points.size());
    std::vector<std::uint8_t> mats(points.size());
    for (int z = box.begin.z; z < box.end.z; ++z)
      for (int y = box.begin.y; y < box.end.y; ++y) {
        for (int x = 0; x < size.x; ++x)
          points[static_cast<std::size_t>(x)] = centre({box.begin.x + x, y, z});
        evaluate(tape, points, values, mats);
        s.evaluated += size.x;
        const std::size_t row = index({box.begin.x, y, z});
        for (std::size_t x = 0; x < points.size(); ++x) {
          materials_[row + x] = values[x] <= 0 ? mats[x] : 0;
          if (field_)
            field_[row + x] =
                static_cast<float>(std::clamp(values[x], -o_.max_distance, o_.max_distance));
        }
      }
  }

  static std::vector<Box3i> halves(const Box3i& box) {
    const Vec3i mid{box.begin.x + (box.end.x - box.begin.x + 1) / 2,
                    box.begin.y + (box.end.y - box.begin.y + 1) / 2,
                    box.begin.z + (box.end.z - box.begin.z + 1) / 2};
    std::vector<Box3i> out;
    for (int octant = 0; octant < 8; ++octant) {
      Box3i c = box;
      for (int a = 0; a < 3; ++a) (octant >> a & 1 ? c.begin[a] : c.end[a]) = mid[a];
      if (!c.empty()) out.push_back(c);
    }
    return out;
  }

  Vec3d centre(Vec3i v) const {
    return out_.box.lo + Vec3d{v.x + 0.5, v.y + 0.5, v.z + 0.5} * o_.voxel_size;
  }
  Bounds centres(const Box3i& box) const {
    return {centre(box.begin), centre(box.end - Vec3i{1, 1, 1})};
  }
  std::size_t index(Vec3i v) const {
    return static_cast<std::size_t>(v.x) +
           static_cast<std::size_t>(out_.dims.x) *
               (static_cast<std::size_t>(v.y) +
                static_cast<std::size_t>(out_.dims.y) * static_cast<std::size_t>(v.z));
  }

  const Voxelized& out_;
  const VoxelizeOptions& o_;
  std::vector<std::uint8_t>& materials_;
  float* field_;  // null unless the field is wanted
};

void add(VoxelizeStats& to, const VoxelizeStats& s) {
  to.evaluated += s.evaluated;
  to.cells += s.cells;
  to.empty_cells += s.empty_cells;
  to.full_cells += s.full_cells;
  to.surface_cells += s.surface_cells;
  to.mean_nodes += s.mean_nodes;  // a sum until the end
  to.max_nodes = std::max(to.max_nodes, s.max_nodes);
}

}  // namespace

Voxelized voxelize(const Model& model, const VoxelizeOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  if (!(options.voxel_size > 0) || !std::isfinite(options.voxel_size))
    throw InvalidArgument("voxel size must be a finite number > 0");
  if (!(options.max_distance > 0)) throw InvalidArgument("max distance must be > 0");
  if (options.leaf_edge < 1 || options.leaf_edge > 256)
    throw InvalidArgument("leaf edge must be 1..256");
  Voxelized out;
  out.box = box_or_bounds(model, options.box);
  const Bounds& b = out.box;
  for (int a = 0; a < 3; ++a) {
    // Whole voxels covering the box; an extent within 1e-6 voxel of a whole number of voxels (a box
    // written with limited digits) is that number.
    const double exact = (b.hi[a] - b.lo[a]) / options.voxel_size;
    double cells = std::ceil(exact);
    if (cells - exact > 1 - 1e-6) cells -= 1;
    if (!std::isfinite(b.lo[a]) || !std::isfinite(b.hi[a]) || !(b.hi[a] >= b.lo[a]))
      throw InvalidArgument(model.name + ": the box must be finite with lo <= hi on every axis");
    if (!(cells <= kCoordLimit))
      throw InvalidArgument(model.name + ": the box is " + std::to_string(cells) +
                            " voxels along an axis, more than 2^29");
    out.dims[a] = std::max(1, static_cast<int>(cells));
  }
  const Box3i grid = Box3i::from_size(out.dims);
  // Dense materials and (when asked) values, then the world's chunks: at most one byte per voxel.
  require_memory(add_sat(dense_bytes(grid, options.field ? 6 : 2), 0), options.memory_limit_bytes,
                 model.name, "voxelising " + to_string(out.dims) + " voxels");
  const Tape whole = compile_tape(model, options.memory_limit_bytes);
  std::vector<std::uint8_t> materials(static_cast<std::size_t>(grid.volume()));
  if (options.field) out.field.resize(materials.size());

  Voxelizer v(out, options, materials, options.field ? out.field.data() : nullptr);
  std::vector<Job> jobs;
  VoxelizeStats total;
  v.split(std::make_shared<const Tape>(whole), grid, jobs, total);
  Progress progress(options.interrupter, "voxelising " + model.name,
                    static_cast<std::int64_t>(jobs.size()));
  std::mutex mutex;
  parallel_for(jobs.size(), 1, [&](std::size_t begin, std::size_t end) {
    VoxelizeStats local;
    for (std::size_t j = begin; j < end && progress.keep_going(); ++j) {
      v.cell(*jobs[j].tape, jobs[j].box, local);
      progress.advance();
    }
    const std::lock_guard lock(mutex);
    add(total, local);
  });
  progress.throw_if_cancelled();
  out.world = World(Grid<std::uint8_t>::kDefaultChunkEdge, grid);
  out.world.palette = model.palette;
  // Voxel (i, j, k)'s centre at box.lo + ((i, j, k) + 1/2) * voxel size: the world's frame.
  out.world.frame.origin_world = out.box.lo;
  out.world.frame.voxel_size_world = Vec3d{1, 1, 1} * options.voxel_size;
  out.world.voxels.copy_from_dense(grid, materials.data());
  total.voxels = grid.volume();
  total.whole_nodes = static_cast<std::int64_t>(whole.code.size());
  total.mean_nodes =
      total.surface_cells ? total.mean_nodes / static_cast<double>(total.surface_cells) : 0;
  total.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  out.stats = total;
  return out;
}

}  // namespace voxfield::csg
