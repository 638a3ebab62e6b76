// voxfield — applying edits to worlds, chunk by chunk, and recording what changed.
#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "voxfield/edit.h"

namespace voxfield {
namespace {

constexpr std::int64_t kMaxEditVoxels = std::int64_t{1} << 33;

}  // namespace

void validate_edit(const Edit& e) {
  struct Check {
    static void finite(const Vec3d& p, const char* what) {
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        throw InvalidArgument(std::string(what) + " must be finite");
      }
    }
    void operator()(const SphereBrush& s) const {
      if (!(s.radius >= 0) || !std::isfinite(s.radius))
        throw InvalidArgument("sphere radius must be >= 0");
      finite(s.center, "sphere centre");
    }
    void operator()(const BoxBrush& b) const {
      if (b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z) {
        throw InvalidArgument("box min " + to_string(b.min) + " exceeds max " + to_string(b.max));
      }
    }
    void operator()(const RotatedBoxBrush& b) const {
      for (double h : {b.half_extent.x, b.half_extent.y, b.half_extent.z})
        if (!(h >= 0) || !std::isfinite(h))
          throw InvalidArgument("rotated box half extents must be >= 0");
      finite(b.center, "rotated box centre");
      finite(b.rotation_deg, "rotated box rotation");
    }
    void operator()(const CapsuleBrush& c) const {
      if (!(c.radius >= 0) || !std::isfinite(c.radius))
        throw InvalidArgument("capsule radius must be >= 0");
      finite(c.a, "capsule end");
      finite(c.b, "capsule end");
    }
    void operator()(const StampBrush& s) const {
      if (!s.model) throw InvalidArgument("stamp without a model");
    }
  };
  std::visit(Check{}, e.brush);
  const bool stamp = std::holds_alternative<StampBrush>(e.brush);
  if (e.op != EditOp::kCarve && !stamp && e.material == 0) {
    throw InvalidArgument("place and paint need a material 1..255 (carve sets air)");
  }
}

DirtyRegions::DirtyRegions(int chunk_edge, Track track) : shift_(0), track_(track) {
  if (chunk_edge < 1 || (chunk_edge & (chunk_edge - 1)) != 0)
    throw InvalidArgument("dirty-region chunk edge must be a power of two");
  while ((1 << shift_) < chunk_edge) ++shift_;
}

void DirtyRegions::add(const Box3i& changed, bool removes_solid, bool adds_solid) {
  if (!changed.empty()) {
    removes_solid_ = removes_solid_ || removes_solid;
    adds_solid_ = adds_solid_ || adds_solid;
  }
  if (changed.empty()) return;
  const Vec3i lo{changed.begin.x >> shift_, changed.begin.y >> shift_, changed.begin.z >> shift_};
  const Vec3i hi{(changed.end.x - 1) >> shift_, (changed.end.y - 1) >> shift_,
                 (changed.end.z - 1) >> shift_};
  const int e = 1 << shift_;
  for (int z = lo.z; z <= hi.z; ++z)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int x = lo.x; x <= hi.x; ++x) {
        const Box3i cb{{x * e, y * e, z * e}, {x * e + e, y * e + e, z * e + e}};
        const Box3i part = cb.intersect(changed);
        auto [it, inserted] = per_chunk_.try_emplace({x, y, z}, part);
        if (!inserted) it->second = it->second.unite(part);
      }
}

std::vector<Box3i> DirtyRegions::boxes() const {
  std::vector<std::pair<Vec3i, Box3i>> all(per_chunk_.begin(), per_chunk_.end());
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return std::tie(a.first.z, a.first.y, a.first.x) < std::tie(b.first.z, b.first.y, b.first.x);
  });
  std::vector<Box3i> out;
  out.reserve(all.size());
  for (const auto& [c, b] : all) out.push_back(b);
  return out;
}

Box3i DirtyRegions::bounds() const {
  Box3i u{{0, 0, 0}, {0, 0, 0}};
  for (const auto& [c, b] : per_chunk_) u = u.unite(b);
  return u;
}

EditResult apply_edit(World& world, const Edit& e, DirtyRegions* dirty) {
  validate_edit(e);
  Box3i box = brush_bounds(e.brush);
  if (world.voxels.bounds()) box = box.intersect(*world.voxels.bounds());
  EditResult result;
  result.changed_box = {{0, 0, 0}, {0, 0, 0}};
  if (box.empty()) return result;
  if (box.volume() > kMaxEditVoxels) {
    throw InvalidArgument("edit covers " + std::to_string(box.volume()) +
                          " voxels; the limit is 2^33");
  }
  const StampBrush* stamp = std::get_if<StampBrush>(&e.brush);
  Grid<std::uint8_t>& g = world.voxels;
  const int edge = g.chunk_edge();
  const Vec3i c0 = g.chunk_of(box.begin), c1 = g.chunk_of(box.end - Vec3i::splat(1));
  Vec3i lo = box.end, hi = box.begin - Vec3i::splat(1);
  for (int cz = c0.z; cz <= c1.z; ++cz)
    for (int cy = c0.y; cy <= c1.y; ++cy)
      for (int cx = c0.x; cx <= c1.x; ++cx) {
        const Vec3i coord{cx, cy, cz};
        const Box3i cb = g.chunk_box(coord);
        const Box3i part = cb.intersect(box);
        // A uniform chunk the operation cannot change is skipped without expanding it.
        const ChunkView<std::uint8_t> view = g.chunk_view(coord);
        if (view.uniform() && !stamp) {
          const std::uint8_t v = view.uniform_value;
          if ((e.op == EditOp::kPlace && v == e.material) || (e.op != EditOp::kPlace && v == 0))
            continue;
        }
        Vec3i clo = part.end, chi = part.begin - Vec3i::splat(1);  // changes inside this chunk
        Vec3i olo = part.end, ohi = part.begin - Vec3i::splat(1);  // solid <-> air changes
        bool removed = false;                                      // any solid -> air
        bool added = false;                                        // any air -> solid
        g.edit_chunk(coord, [&](Grid<std::uint8_t>::ChunkEdit& voxels) {
          // One voxel the brush covers.
          auto visit = [&](int x, int y, int z) {
            const Vec3i p{x, y, z};
            const std::int64_t i =
                (std::int64_t{z - cb.begin.z} * edge + (y - cb.begin.y)) * edge + (x - cb.begin.x);
            const std::uint8_t before = voxels.get(i);
            const std::uint8_t paint =
                stamp ? stamp->model->voxels.get(p - stamp->offset) : e.material;
            std::uint8_t next = before;
            switch (e.op) {
              case EditOp::kPlace:
                next = paint;
                break;
              case EditOp::kCarve:
                next = 0;
                break;
              case EditOp::kPaint:
                next = before != 0 ? paint : before;
                break;
            }
            if (!voxels.set(i, next)) return;
            ++result.voxels_changed;
            clo = {std::min(clo.x, x), std::min(clo.y, y), std::min(clo.z, z)};
            chi = {std::max(chi.x, x), std::max(chi.y, y), std::max(chi.z, z)};
            if ((next != 0) != (before != 0)) {
              removed = removed || next == 0;
              added = added || next != 0;
              olo = {std::min(olo.x, x), std::min(olo.y, y), std::min(olo.z, z)};
              ohi = {std::max(ohi.x, x), std::max(ohi.y, y), std::max(ohi.z, z)};
            }
          };
          // A run of covered voxels [a, b] of row (y, z). Placing and carving write one value, so
          // the run's bookkeeping (changed boxes, what changed) is settled once per run.
          auto visit_run = [&](int a, int b, int y, int z) {
            if (stamp || e.op == EditOp::kPaint) {
              for (int x = a; x <= b; ++x) visit(x, y, z);
              return;
            }
            const std::uint8_t next = e.op == EditOp::kPlace ? e.material : std::uint8_t{0};
            const std::int64_t row =
                (std::int64_t{z - cb.begin.z} * edge + (y - cb.begin.y)) * edge - cb.begin.x;
            int first = INT32_MAX, last = INT32_MIN, first_flip = INT32_MAX, last_flip = INT32_MIN;
            std::int64_t changed = 0;
            for (int x = a; x <= b; ++x) {
              const std::uint8_t before = voxels.get(row + x);
              if (!voxels.set(row + x, next)) continue;
              ++changed;
              first = std::min(first, x);
              last = x;
              if ((before != 0) != (next != 0)) {
                first_flip = std::min(first_flip, x);
                last_flip = x;
              }
            }
            if (changed == 0) return;
            result.voxels_changed += changed;
            clo = {std::min(clo.x, first), std::min(clo.y, y), std::min(clo.z, z)};
            chi = {std::max(chi.x, last), std::max(chi.y, y), std::max(chi.z, z)};
            if (first_flip <= last_flip) {
              removed = removed || next == 0;
              added = added || next != 0;
              olo = {std::min(olo.x, first_flip), std::min(olo.y, y), std::min(olo.z, z)};
              ohi = {std::max(ohi.x, last_flip), std::max(ohi.y, y), std::max(ohi.z, z)};
            }
          };
          // The brush is resolved once per chunk, not once per voxel.
          std::visit(
              [&](const auto& shape) {
                using Shape = std::decay_t<decltype(shape)>;
                for (int z = part.begin.z; z < part.end.z; ++z)
                  for (int y = part.begin.y; y < part.end.y; ++y) {
                    if constexpr (std::is_same_v<Shape, SphereBrush>) {
                      // A sphere covers one run of each row: its test grows with |x - centre.x|
                      // alone (rounding keeps that monotone), so the run holds the row's voxel
                      // nearest the centre, m, or the row holds none. The run's ends are estimated,
                      // then settled with the test itself: exactly the voxels the test accepts.
                      const double x0 = part.begin.x, x1 = part.end.x - 1;
                      const int m =
                          static_cast<int>(std::clamp(std::round(shape.center[0]), x0, x1));
                      if (!brush_contains(shape, {m, y, z})) continue;
                      const double dy = y - shape.center[1], dz = z - shape.center[2];
                      const double half =
                          std::sqrt(std::max(0.0, shape.radius * shape.radius - dy * dy - dz * dz));
                      int a = static_cast<int>(std::clamp(std::ceil(shape.center[0] - half), x0,
                                                          static_cast<double>(m)));
                      int b = static_cast<int>(std::clamp(std::floor(shape.center[0] + half),
                                                          static_cast<double>(m), x1));
                      while (a > part.begin.x && brush_contains(shape, {a - 1, y, z})) --a;
                      while (!brush_contains(shape, {a, y, z})) ++a;  // stops at m at the latest
                      while (b < part.end.x - 1 && brush_contains(shape, {b + 1, y, z})) ++b;
                      while (!brush_contains(shape, {b, y, z})) --b;
                      visit_run(a, b, y, z);
                    } else if constexpr (std::is_same_v<Shape, BoxBrush>) {
                      // The part of the chunk is already clipped to the box: every row is one run.
                      visit_run(part.begin.x, part.end.x - 1, y, z);
                    } else {
                      for (int x = part.begin.x; x < part.end.x; ++x)
                        if (brush_contains(shape, {x, y, z})) visit(x, y, z);
                    }
                  }
              },
              e.brush);
        });
        if (chi.x >= clo.x) {
          const Box3i changed = Box3i::from_inclusive(clo, chi);
          if (dirty && dirty->track() == DirtyRegions::Track::kAnyChange)
            dirty->add(changed, removed, added);
          if (dirty && dirty->track() == DirtyRegions::Track::kOccupancy && ohi.x >= olo.x) {
            dirty->add(Box3i::from_inclusive(olo, ohi), removed, added);
          }
          lo = {std::min(lo.x, clo.x), std::min(lo.y, clo.y), std::min(lo.z, clo.z)};
          hi = {std::max(hi.x, chi.x), std::max(hi.y, chi.y), std::max(hi.z, chi.z)};
        }
      }
  if (result.voxels_changed > 0) result.changed_box = Box3i::from_inclusive(lo, hi);
  return result;
}

}  // namespace voxfield
