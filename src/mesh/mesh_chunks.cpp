// voxfield — MeshChunks: the per-chunk parts of the chunked driver (chunked_mesh.h), kept between
// edits. Which chunks an edit reaches follows from what a chunk reads: its cells' corners, one
// cell before it (the dual meshers' apron) and the gradient stencils around them — samples from
// three before its first cell to two past its last corner (dual contouring's one-sided
// differences reach two samples out).
#include "voxfield/mesh_chunks.h"

#include <string>

#include "mesh_internal.h"
#include "voxfield/error.h"

namespace voxfield {

struct MeshChunks::Impl {
  MeshOptions options;
  ScalarVolume frame;  // size, origin and spacing the chunks were meshed with
  // What the chunks were meshed from: a volume, or a terrain (with or without a palette). An
  // update must come from the same kind of source, so that every part has colours or none does.
  enum class Source { kVolume, kTerrain, kColouredTerrain } source = Source::kVolume;
  void check_source(Source given) const;
  detail::mesh::ChunkGrid grid{{2, 2, 2}, 2};
  std::vector<detail::mesh::ChunkPart> parts;

  void mesh_all(const detail::mesh::Lattice& lattice);
  // Re-meshes the chunks whose reads meet `changed`; returns them.
  std::vector<Vec3i> update(const detail::mesh::Lattice& lattice, const Box3i& changed);
  void check_frame(const ScalarVolume& volume) const;
};

void MeshChunks::Impl::mesh_all(const detail::mesh::Lattice& lattice) {
  grid = detail::mesh::ChunkGrid(frame.size, options.chunk_edge);
  parts = detail::mesh::mesh_all_chunks(lattice, options);
  options.interrupter = nullptr;  // it watched the first mesh; the chunks outlive it
}

void MeshChunks::Impl::check_source(Source given) const {
  if (given == source) return;
  auto name = [](Source s) {
    return s == Source::kVolume    ? "a volume"
           : s == Source::kTerrain ? "a terrain without a palette"
                                   : "a terrain with a palette";
  };
  throw InvalidArgument(std::string("MeshChunks::update: the chunks were meshed from ") +
                        name(source) + ", the update gives " + name(given) +
                        "; build a new MeshChunks");
}

void MeshChunks::Impl::check_frame(const ScalarVolume& volume) const {
  if (!(volume.size == frame.size) || volume.origin_units != frame.origin_units ||
      volume.spacing_units != frame.spacing_units)
    throw InvalidArgument(
        "MeshChunks::update: the volume's size or frame changed; build a new MeshChunks");
}

MeshChunks::MeshChunks(const ScalarVolume& volume, const MeshOptions& options)
    : impl_(std::make_unique<Impl>()) {
  const detail::mesh::Lattice lattice = detail::mesh::checked_lattice(volume, options, false);
  impl_->options = options;
  impl_->frame = volume;
  impl_->frame.values = nullptr;
  impl_->mesh_all(lattice);
}

MeshChunks::MeshChunks(const TerrainField& terrain, const MeshOptions& options)
    : impl_(std::make_unique<Impl>()) {
  using namespace detail::mesh;
  impl_->options = terrain_options(terrain, options);
  impl_->frame = terrain_frame(terrain);
  impl_->source =
      terrain.options().palette ? Impl::Source::kColouredTerrain : Impl::Source::kTerrain;
  TerrainSamples keep;
  impl_->mesh_all(terrain_lattice(terrain, impl_->options, keep));
}

std::vector<Vec3i> MeshChunks::update(const TerrainField& terrain, const Box3i& changed) {
  using namespace detail::mesh;
  impl_->check_source(terrain.options().palette ? Impl::Source::kColouredTerrain
                                                : Impl::Source::kTerrain);
  impl_->check_frame(terrain_frame(terrain));
  if (terrain_options(terrain, impl_->options).inside_above != impl_->options.inside_above)
    throw InvalidArgument("MeshChunks::update: the terrain's sign convention changed");
  TerrainSamples keep;
  return impl_->update(terrain_lattice(terrain, impl_->options, keep), changed);
}

MeshChunks::~MeshChunks() = default;
MeshChunks::MeshChunks(MeshChunks&&) noexcept = default;
MeshChunks& MeshChunks::operator=(MeshChunks&&) noexcept = default;

std::vector<Vec3i> MeshChunks::update(const ScalarVolume& volume, const Box3i& changed) {
  impl_->check_source(Impl::Source::kVolume);
  impl_->check_frame(volume);
  return impl_->update(detail::mesh::checked_lattice(volume, impl_->options, false), changed);
}

std::vector<Vec3i> MeshChunks::Impl::update(const detail::mesh::Lattice& lattice,
                                            const Box3i& changed) {
  using namespace detail::mesh;
  Impl& s = *this;
  const Box3i region = changed.intersect(Box3i::from_size(frame.size));
  std::vector<std::int64_t> dirty;
  std::vector<Vec3i> coords;
  if (!region.empty()) {
    // Chunk k along an axis reads samples [k * edge - 3, end + 2], end its last cell's upper
    // corner.
    Vec3i lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, (region.begin[a] - 2) / s.grid.edge - 1);
      hi[a] = std::min(s.grid.count[a] - 1, (region.end[a] - 1 + 3) / s.grid.edge);
    }
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const Box3i cells = s.grid.cells_of({x, y, z});
          Box3i reads;
          for (int a = 0; a < 3; ++a) {
            reads.begin[a] = cells.begin[a] - 3;
            reads.end[a] = cells.end[a] + 3;  // exclusive: corners up to end, stencils two past
          }
          if (reads.intersect(region).empty()) continue;
          dirty.push_back(x + static_cast<std::int64_t>(s.grid.count.x) *
                                  (y + static_cast<std::int64_t>(s.grid.count.y) * z));
          coords.push_back({x, y, z});
        }
  }
  std::vector<ChunkPart> fresh(dirty.size());
  mesh_chunks(lattice, s.grid, s.options, dirty, fresh);  // built aside: a throw changes nothing
  for (std::size_t i = 0; i < dirty.size(); ++i)
    std::swap(s.parts[static_cast<std::size_t>(dirty[i])], fresh[i]);
  return coords;
}

Vec3i MeshChunks::chunk_count() const {
  return impl_->grid.count;
}

Mesh MeshChunks::chunk_mesh(Vec3i c) const {
  const Impl& s = *impl_;
  for (int a = 0; a < 3; ++a)
    if (c[a] < 0 || c[a] >= s.grid.count[a])
      throw InvalidArgument("MeshChunks::chunk_mesh: chunk " + to_string(c) + " is outside the " +
                            to_string(s.grid.count) + " chunks");
  const auto& p = s.parts[static_cast<std::size_t>(
      c.x + static_cast<std::int64_t>(s.grid.count.x) *
                (c.y + static_cast<std::int64_t>(s.grid.count.y) * c.z))];
  Mesh m;
  m.positions = p.positions;
  m.normals = p.normals;
  m.colors = p.colors;
  m.indices = p.indices;
  return m;
}

Mesh MeshChunks::merged() const {
  return detail::mesh::weld(impl_->parts, nullptr);
}

}  // namespace voxfield
