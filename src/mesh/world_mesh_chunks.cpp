// voxfield — WorldMeshChunks (mesh_chunks.h): a voxel world's surface kept chunk by chunk through
// its edits.
//
// The chunks read the samples of the world's signed field as mesh_world() does (mesh_world.cpp:
// the same clamp, lattice, normals and colours), but over a lattice fixed by the world's bounds
// instead of its content, so that an edit moves no chunk. The field is a DynamicDistanceField,
// exact after every update, so a chunk re-meshed from it is the chunk a full mesh would give; which
// chunks an edit reaches follows from the field's reach (values move up to the clamp from a
// changed voxel; an offset surface's colours and normals come from nearest sites within it) and
// from what a chunk reads (kept_chunks.h). Each chunk's block copies the field's values it reads
// (Grid::copy_to_dense), so no dense copy of the whole field is made.
#include <optional>
#include <string>

#include "kept_chunks.h"
#include "mesh_internal.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/error.h"
#include "voxfield/mesh_chunks.h"

namespace voxfield {

struct WorldMeshChunks::Impl {
  const World* world = nullptr;
  Metric metric = Metric::kEuclidean;
  std::optional<Box3i> world_bounds;  // the world's bounds when bound (they must not change)
  Box3i bounds;  // the voxels meshed: the world's bounds, or the box given (cut to them)
  Box3i domain;  // the lattice's voxels: `bounds` grown by the air around the surface
  // The world's voxels without bounds: the field reaches past the bounds, where the world stores
  // nothing (air there, read as the background), and a bounded grid's field could not hold it.
  World unbounded;
  std::optional<DynamicDistanceField> field;  // bound to `unbounded`
  detail::mesh::KeptChunks kept;
  std::function<void(const Box3i&, float*)> fill;
  std::function<std::array<std::uint8_t, 3>(std::uint64_t)> color;

  detail::mesh::Lattice lattice() const {
    detail::mesh::Lattice l =
        detail::mesh::checked_lattice(detail::mesh::world_lattice_frame(domain), kept.options,
                                      /*voxel_faces=*/kept.options.iso == 0, &fill);
    l.color = &color;
    return l;
  }
  // The world's voxels inside `bounds`, without bounds.
  void copy_world() {
    const int edge = world->voxels.chunk_edge();
    unbounded.voxels = world->voxels.bounds() == bounds
                           ? world->voxels.rechunked(edge, std::nullopt)
                           : world->voxels.rechunked(edge, bounds).rechunked(edge, std::nullopt);
  }
  void check_bounds() const {
    if (world->voxels.bounds() != world_bounds)
      throw InvalidArgument(
          "WorldMeshChunks: the world's bounds changed; build a new WorldMeshChunks");
  }
};

WorldMeshChunks::WorldMeshChunks(const World& world, const MeshOptions& options, Metric metric,
                                 std::optional<Box3i> box)
    : impl_(std::make_unique<Impl>()) {
  using namespace detail::mesh;
  Impl& s = *impl_;
  if (!box && !world.voxels.bounds())
    throw InvalidArgument(
        "WorldMeshChunks: the world has no bounds and no box was given; a kept mesh needs a fixed "
        "lattice (give a box, or mesh it once with mesh_world)");
  const int margin = world_surface_margin(options.iso);
  if (box)
    for (int a = 0; a < 3; ++a)
      if (!bound_in_range(box->begin[a]) || !bound_in_range(box->end[a]))
        throw InvalidArgument("WorldMeshChunks: the box " + to_string(*box) +
                              " leaves the supported coordinate range");
  s.world = &world;
  s.metric = metric;
  s.world_bounds = world.voxels.bounds();
  s.bounds = box ? (s.world_bounds ? box->intersect(*s.world_bounds) : *box) : *s.world_bounds;
  if (s.bounds.empty())
    throw InvalidArgument(box ? "WorldMeshChunks: the box " + to_string(*box) +
                                    " holds no voxel of the world"
                              : std::string("WorldMeshChunks: the world's bounds are empty"));
  s.domain = s.bounds.grown(margin);
  s.kept.options = options;
  s.kept.options.inside_above = false;
  s.fill = [&s](const Box3i& region, float* out) {
    const Box3i voxels{region.begin + s.domain.begin, region.end + s.domain.begin};
    std::get<Grid<float>>(s.field->field().values).copy_to_dense(voxels, out);
  };
  const Vec3i n = s.domain.size();
  s.color = [&s, n](std::uint64_t index) {
    const auto nx = static_cast<std::uint64_t>(n.x), ny = static_cast<std::uint64_t>(n.y);
    const Vec3i p{s.domain.begin.x + static_cast<int>(index % nx),
                  s.domain.begin.y + static_cast<int>(index / nx % ny),
                  s.domain.begin.z + static_cast<int>(index / nx / ny)};
    // The material from the voxels meshed (outside a box: air, whatever the world holds there).
    const Rgba c = s.world->palette[world_vertex_material(s.unbounded, s.field->field(), p)];
    return std::array<std::uint8_t, 3>{c.r, c.g, c.b};
  };
  (void)s.lattice();  // the options checked (chunk edge, frame) before the field is built

  s.unbounded = World(world.voxels.chunk_edge());
  s.copy_world();
  DistanceOptions field_options = world_field_options(options.iso, metric, s.domain);
  field_options.interrupter = options.interrupter;
  s.field.emplace(s.unbounded, field_options);
  if (options.iso != 0)
    s.kept.options.gradient =
        offset_gradient(s.unbounded, s.field->field(), metric, options.iso > 0);
  s.kept.mesh_all(s.lattice());
}

WorldMeshChunks::~WorldMeshChunks() = default;
WorldMeshChunks::WorldMeshChunks(WorldMeshChunks&&) noexcept = default;
WorldMeshChunks& WorldMeshChunks::operator=(WorldMeshChunks&&) noexcept = default;

std::vector<Vec3i> WorldMeshChunks::update(const DirtyRegions& dirty) {
  Impl& s = *impl_;
  s.check_bounds();
  // Occupancy alone misses repaints, which change no distance but the colours: refused rather
  // than left stale.
  if (dirty.track() != DirtyRegions::Track::kAnyChange)
    throw InvalidArgument(
        "WorldMeshChunks::update: the changes were recorded for occupancy only; a repaint "
        "re-colours the mesh, so record them with DirtyRegions::Track::kAnyChange");
  if (dirty.empty()) return {};
  const std::vector<Box3i> boxes = dirty.boxes();
  // The copy first (the field reads it), box by box: the edits' boxes, not the world.
  std::vector<std::uint8_t> voxels;
  for (const Box3i& box : boxes) {
    const Box3i b = box.intersect(s.bounds);
    if (b.empty()) continue;
    voxels.resize(static_cast<std::size_t>(b.volume()));
    s.world->voxels.copy_to_dense(b, voxels.data());
    s.unbounded.voxels.copy_from_dense(b, voxels.data());
  }
  s.field->update(dirty);  // (nothing to do for repaints alone: only colours, read from the copy)
  // The samples whose value, colour or nearest site may have moved: each change grown by the
  // field's reach, in the lattice's coordinates.
  const Vec3i reach = s.field->reach();
  std::vector<Box3i> changed;
  changed.reserve(boxes.size());
  for (const Box3i& box : boxes)
    changed.push_back({box.begin - reach - s.domain.begin, box.end + reach - s.domain.begin});
  return s.kept.update(s.lattice(), changed);
}

void WorldMeshChunks::rebuild() {
  Impl& s = *impl_;
  s.check_bounds();
  s.copy_world();
  s.field->rebuild();
  s.kept.mesh_all(s.lattice());
}

Vec3i WorldMeshChunks::chunk_count() const {
  return impl_->kept.grid.count;
}

Mesh WorldMeshChunks::chunk_mesh(Vec3i c) const {
  Mesh m = impl_->kept.chunk_mesh(c, "WorldMeshChunks");
  place_in_frame(m, impl_->world->frame);
  return m;
}

Mesh WorldMeshChunks::merged() const {
  Mesh m = impl_->kept.merged();
  place_in_frame(m, impl_->world->frame);
  return m;
}

const DistanceField& WorldMeshChunks::field() const {
  return impl_->field->field();
}

}  // namespace voxfield
