// voxfield render — CSG models by sphere tracing (Hart, "Sphere Tracing: A Geometric Method for
// the Antialiased Ray Tracing of Implicit Surfaces", 1996) through the voxel compiler's octree
// (Palecek, "A Better Approach to SDF Decomposition": each cell drawn with its own small
// evaluator). Rays visit the octree's cells front to back and stop at the first hit, so cells
// behind the surface and empty cells cost nothing; within a surface cell the march uses that
// cell's pruned tape, which equals the whole model there. Bound and exact tapes are 1-Lipschitz,
// so a step of the value never passes the surface; a tape with an ellipsoid (approximate) steps
// by half the value.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include "csg_frame.h"
#include "shading.h"
#include "voxfield/csg_render.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"

namespace voxfield {
namespace {

using render_detail::Rgb;

constexpr int kMaxStepsPerCell = 256;

// The ray's parameter interval inside a box (empty when t0 > t1).
std::pair<double, double> slab(const Ray& ray, const Vec3d& inv, const csg::Bounds& b) {
  double t0 = -std::numeric_limits<double>::infinity(),
         t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    double lo = (b.lo[a] - ray.origin[a]) * inv[a], hi = (b.hi[a] - ray.origin[a]) * inv[a];
    if (lo > hi) std::swap(lo, hi);
    if (std::isnan(lo))
      lo = -std::numeric_limits<double>::infinity();  // parallel ray inside the slab
    if (std::isnan(hi)) hi = std::numeric_limits<double>::infinity();
    t0 = std::max(t0, lo);
    t1 = std::min(t1, hi);
  }
  return {t0, t1};
}

struct Hit {
  double t = -1;
  int leaf = -1;  // the octree leaf it was found in (-1: whole-tape tracing)
};

struct Counters {
  std::int64_t evaluations = 0, instructions = 0, cells = 0;
};

class Tracer {
 public:
  Tracer(const csg::Tape& whole, const csg::Octree* tree, const csg::Bounds& box, double epsilon)
      : whole_(whole), tree_(tree), box_(box), epsilon_(epsilon), id_(next_id_.fetch_add(1) + 1) {}

  Hit trace(const Ray& ray, double tmin, double tmax, Counters& c) const {
    const Vec3d inv{1 / ray.direction.x, 1 / ray.direction.y, 1 / ray.direction.z};
    auto [t0, t1] = slab(ray, inv, box_);
    t0 = std::max(t0, tmin);
    t1 = std::min(t1, tmax);
    if (t0 > t1) return {};
    if (!tree_) return march(whole_, whole_.code.back().lipschitz, ray, t0, t1, -1, c);
    return node(tree_->children[0], tree_->root, ray, inv, t0, t1, c);
  }

  // The tape to evaluate near a hit: the leaf's pruned tape, or the whole one.
  const csg::Tape& tape_of(int leaf) const {
    const bool surface = leaf >= 0 && tree_->leaves[static_cast<std::size_t>(leaf)].state ==
                                          csg::CellState::kSurface;
    return surface ? leaf_tape(leaf) : whole_;
  }

 private:
  Hit node(std::int32_t entry, const csg::Bounds& box, const Ray& ray, const Vec3d& inv,
           double tmin, double tmax, Counters& c) const {
    if (entry < 0) {
      const int leaf = -entry - 1;
      const csg::OctreeLeaf& l = tree_->leaves[static_cast<std::size_t>(leaf)];
      if (l.state == csg::CellState::kEmpty) return {};
      if (l.state == csg::CellState::kFull) return {tmin, leaf};  // the surface is at its face
      ++c.cells;
      const csg::Tape& t = leaf_tape(leaf);
      return march(t, t.code.back().lipschitz, ray, tmin, tmax, leaf, c);
    }
    // Children in the order the ray enters them.
    struct Child {
      double t0, t1;
      int octant;
      csg::Bounds box;
    };
    Child order[8];
    int n = 0;
    const Vec3d mid = (box.lo + box.hi) * 0.5;
    for (int octant = 0; octant < 8; ++octant) {
      csg::Bounds b = box;
      for (int a = 0; a < 3; ++a) (octant >> a & 1 ? b.lo[a] : b.hi[a]) = mid[a];
      auto [t0, t1] = slab(ray, inv, b);
      t0 = std::max(t0, tmin);
      t1 = std::min(t1, tmax);
      if (t0 > t1) continue;
      int i = n++;
      for (; i > 0 && order[i - 1].t0 > t0; --i) order[i] = order[i - 1];
      order[i] = {t0, t1, octant, b};
    }
    for (int i = 0; i < n; ++i) {
      const Hit h = node(tree_->children[static_cast<std::size_t>(entry + order[i].octant)],
                         order[i].box, ray, inv, order[i].t0, order[i].t1, c);
      if (h.t >= 0) return h;
    }
    return {};
  }

  Hit march(const csg::Tape& tape, bool lipschitz, const Ray& ray, double t0, double t1, int leaf,
            Counters& c) const {
    const double factor = lipschitz ? 1.0 : 0.5;
    double t = t0;
    for (int step = 0; step < kMaxStepsPerCell && t <= t1; ++step) {
      const Vec3d p = ray.origin + ray.direction * t;
      const double v = csg::evaluate(tape, p);
      ++c.evaluations;
      c.instructions += static_cast<std::int64_t>(tape.code.size());
      if (v < epsilon_) return {t, leaf};
      t += std::max(v * factor, epsilon_ * 0.5);
    }
    return {};
  }

  // A surface leaf's tape, kept per thread while consecutive rays stay in the same cell (keyed by
  // the tracer's id, so that a later render never reads an earlier one's cache).
  const csg::Tape& leaf_tape(int leaf) const {
    thread_local std::uint64_t cached_id = 0;
    thread_local int cached_leaf = -1;
    thread_local csg::Tape cached;
    if (cached_id != id_ || cached_leaf != leaf) {
      cached = tree_->leaf_tape(tree_->leaves[static_cast<std::size_t>(leaf)]);
      cached_id = id_;
      cached_leaf = leaf;
    }
    return cached;
  }

  const csg::Tape& whole_;
  const csg::Octree* tree_;
  csg::Bounds box_;
  double epsilon_;
  std::uint64_t id_;
  static inline std::atomic<std::uint64_t> next_id_{0};
};

}  // namespace

namespace render_detail {

Rgb variant_colour(int variant) {
  const double h = std::fmod(0.13 + variant * 0.6180339887, 1.0) * 6;
  const double x = 1 - std::abs(std::fmod(h, 2.0) - 1);
  Rgb c = h < 1   ? Rgb{1, x, 0}
          : h < 2 ? Rgb{x, 1, 0}
          : h < 3 ? Rgb{0, 1, x}
          : h < 4 ? Rgb{0, x, 1}
          : h < 5 ? Rgb{x, 0, 1}
                  : Rgb{1, 0, x};
  return c * 0.55 + Rgb{0.05, 0.05, 0.05};
}

CsgFrame prepare_csg_frame(const csg::Model& model, const CsgRenderOptions& o) {
  // A model is traced in its own units: a camera placed in a world of non-cubic voxels carries
  // its rays into that world's voxels, which are not the model's.
  if (o.camera && o.camera->world_frame)
    throw InvalidArgument(
        "CSG render: a camera placed in a world of non-cubic voxels draws voxels; give the "
        "model's camera in the model's units");
  CsgFrame f;
  std::optional<csg::Bounds> box = csg::box_or_bounds(model, o.box);
  {  // a little margin, so that surfaces on the bounds are inside the traced box
    const Vec3d size = box->hi - box->lo;
    const double margin = 1e-3 * std::max({size.x, size.y, size.z, 1e-9});
    box = csg::Bounds{box->lo - Vec3d{1, 1, 1} * margin, box->hi + Vec3d{1, 1, 1} * margin};
  }
  const auto start = std::chrono::steady_clock::now();
  f.whole = csg::compile_tape(model);
  if (o.prune) {
    csg::OctreeOptions oo;
    oo.depth = o.depth;
    oo.box = box;
    oo.interrupter = o.interrupter;
    // The octree is cubic: grow the box to a cube around its centre.
    const Vec3d size = box->hi - box->lo, centre = (box->lo + box->hi) * 0.5;
    const double edge = std::max({size.x, size.y, size.z});
    oo.box =
        csg::Bounds{centre - Vec3d{1, 1, 1} * (edge / 2), centre + Vec3d{1, 1, 1} * (edge / 2)};
    f.tree = csg::build_octree(f.whole, model, oo);
  }
  f.traced_box = f.tree ? f.tree->root : *box;
  f.octree_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  f.camera = o.camera ? *o.camera : csg_camera(*box, static_cast<double>(o.width) / o.height);
  const Vec3d size = f.traced_box.hi - f.traced_box.lo;
  f.epsilon = 1e-4 * std::max({size.x, size.y, size.z});
  return f;
}

}  // namespace render_detail

Camera csg_camera(const csg::Bounds& box, double aspect) {
  // Camera::framing works on voxel boxes; framing is invariant under scaling and translation, so
  // frame the box centred at the origin and scaled to 4096 units, then map the camera back.
  const Vec3d size = box.hi - box.lo, centre = (box.lo + box.hi) * 0.5;
  const double k = 4096 / std::max({size.x, size.y, size.z, 1e-300});
  const Box3i scaled{
      {static_cast<int>(std::floor(-size.x / 2 * k)), static_cast<int>(std::floor(-size.y / 2 * k)),
       static_cast<int>(std::floor(-size.z / 2 * k))},
      {static_cast<int>(std::ceil(size.x / 2 * k)), static_cast<int>(std::ceil(size.y / 2 * k)),
       static_cast<int>(std::ceil(size.z / 2 * k))}};
  Camera c = Camera::framing(scaled, aspect);
  c.eye = c.eye * (1 / k) + centre;
  c.target = c.target * (1 / k) + centre;
  return c;
}

Image render_csg(const csg::Model& model, const CsgRenderOptions& o, CsgRenderStats* stats) {
  Image image(o.width, o.height);
  const render_detail::CsgFrame frame = render_detail::prepare_csg_frame(model, o);
  const csg::Tape& whole = frame.whole;
  const std::optional<csg::Octree>& tree = frame.tree;
  const csg::Bounds& traced_box = frame.traced_box;
  const double octree_ms = frame.octree_ms;
  const Camera& camera = frame.camera;
  const Camera::Projector proj = camera.projector(o.width, o.height);
  const double epsilon = frame.epsilon;
  const Tracer tracer(whole, tree ? &*tree : nullptr, traced_box, epsilon);
  const Vec3d sun = RenderOptions{}.sun_direction.normalized();
  std::array<Rgb, 256> albedo;
  for (int m = 0; m < 256; ++m)
    albedo[static_cast<std::size_t>(m)] = {
        render_detail::srgb_to_linear(model.palette[static_cast<std::size_t>(m)].r),
        render_detail::srgb_to_linear(model.palette[static_cast<std::size_t>(m)].g),
        render_detail::srgb_to_linear(model.palette[static_cast<std::size_t>(m)].b)};
  Progress progress(o.interrupter, "rendering " + model.name, o.height);
  std::atomic<std::int64_t> evaluations{0}, instructions{0}, cells{0}, hits{0};
  const auto render_start = std::chrono::steady_clock::now();
  parallel_for(static_cast<std::size_t>(o.height), 4, [&](std::size_t y0, std::size_t y1) {
    Counters c;
    std::int64_t row_hits = 0;
    for (std::size_t y = y0; y < y1 && progress.keep_going(); ++y) {
      for (int x = 0; x < o.width; ++x) {
        const Ray ray = proj.ray(x + 0.5, static_cast<double>(y) + 0.5);
        const Hit h = tracer.trace(ray, 0, std::numeric_limits<double>::infinity(), c);
        Rgb colour = render_detail::sky(ray.direction);
        if (h.t >= 0) {
          ++row_hits;
          const Vec3d p = ray.origin + ray.direction * h.t;
          // Normal and material from the hit cell's tape: six samples around p and p itself.
          const csg::Tape& tape = tracer.tape_of(h.leaf);
          const double e = epsilon * 2;
          const Vec3d pts[7] = {p + Vec3d{e, 0, 0},
                                p - Vec3d{e, 0, 0},
                                p + Vec3d{0, e, 0},
                                p - Vec3d{0, e, 0},
                                p + Vec3d{0, 0, e},
                                p - Vec3d{0, 0, e},
                                p};
          double v[7];
          std::uint8_t m[7];
          csg::evaluate(tape, pts, v, m);
          c.evaluations += 7;
          c.instructions += 7 * static_cast<std::int64_t>(tape.code.size());
          Vec3d n{v[0] - v[1], v[2] - v[3], v[4] - v[5]};
          n = n.length() > 0 ? n.normalized() : ray.direction * -1.0;
          if (dot(n, ray.direction) > 0) n = n * -1.0;
          Rgb base = albedo[m[6]];
          if (o.view == CsgRenderOptions::View::kVariants)
            base = h.leaf >= 0 ? render_detail::variant_colour(
                                     tree->leaves[static_cast<std::size_t>(h.leaf)].variant)
                               : Rgb{0.3, 0.3, 0.3};
          const double ndotl = std::max(0.0, dot(n, sun));
          double shadow = 1;
          if (o.shadows && ndotl > 0) {
            const Ray to_sun{p + n * (epsilon * 4), sun};
            if (tracer.trace(to_sun, 0, std::numeric_limits<double>::infinity(), c).t >= 0)
              shadow = 0;
          }
          const Rgb ambient = render_detail::mix(render_detail::kGround, render_detail::kSkyAmbient,
                                                 0.5 + 0.5 * n.z);
          colour = base * (render_detail::kSunLight * (ndotl * shadow) + ambient);
        }
        render_detail::tone_map().write(colour, image.pixel(x, static_cast<int>(y)));
      }
      progress.advance();
    }
    evaluations += c.evaluations;
    instructions += c.instructions;
    cells += c.cells;
    hits += row_hits;
  });
  progress.throw_if_cancelled();
  if (stats) {
    stats->octree_ms = octree_ms;
    stats->render_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - render_start)
            .count();
    stats->rays = static_cast<std::int64_t>(o.width) * o.height;
    stats->hits = hits;
    stats->evaluations = evaluations;
    stats->instructions = instructions;
    stats->cells_entered = cells;
    stats->variants = tree ? static_cast<int>(tree->variants.size()) : 1;
  }
  return image;
}

}  // namespace voxfield
