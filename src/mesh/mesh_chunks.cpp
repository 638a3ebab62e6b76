// voxfield — MeshChunks: the per-chunk parts of the chunked driver (chunked_mesh.h), kept between
// edits of a volume or a terrain field (and, for WorldMeshChunks, a world: world_mesh_chunks.cpp);
// which chunks an edit reaches: kept_chunks.h.
#include "voxfield/mesh_chunks.h"

#include <algorithm>
#include <string>

#include "kept_chunks.h"
#include "mesh_internal.h"
#include "voxfield/error.h"

namespace voxfield {

namespace detail::mesh {

void KeptChunks::mesh_all(const Lattice& lattice) {
  grid = ChunkGrid(lattice.n, options.chunk_edge);
  parts = mesh_all_chunks(lattice, options);
  options.interrupter = nullptr;  // it watched the first mesh; the chunks outlive it
}

std::vector<Vec3i> KeptChunks::update(const Lattice& lattice, const std::vector<Box3i>& changed) {
  std::vector<std::uint8_t> marked(static_cast<std::size_t>(grid.total()), 0);
  std::vector<std::int64_t> dirty;
  std::vector<Vec3i> coords;
  for (const Box3i& change : changed) {
    const Box3i region = change.intersect(Box3i::from_size(lattice.n));
    if (region.empty()) continue;
    // Chunk k along an axis reads samples [k * edge - 3, end + 2], end its last cell's upper
    // corner.
    Vec3i lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, (region.begin[a] - 2) / grid.edge - 1);
      hi[a] = std::min(grid.count[a] - 1, (region.end[a] - 1 + 3) / grid.edge);
    }
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) {
          const std::int64_t i = x + static_cast<std::int64_t>(grid.count.x) *
                                         (y + static_cast<std::int64_t>(grid.count.y) * z);
          if (marked[static_cast<std::size_t>(i)]) continue;
          const Box3i cells = grid.cells_of({x, y, z});
          Box3i reads;
          for (int a = 0; a < 3; ++a) {
            reads.begin[a] = cells.begin[a] - 3;
            reads.end[a] = cells.end[a] + 3;  // exclusive: corners up to end, stencils two past
          }
          if (reads.intersect(region).empty()) continue;
          marked[static_cast<std::size_t>(i)] = 1;
          dirty.push_back(i);
        }
  }
  std::sort(dirty.begin(), dirty.end());
  for (const std::int64_t i : dirty) coords.push_back(grid.coord(i));
  std::vector<ChunkPart> fresh(dirty.size());
  mesh_chunks(lattice, grid, options, dirty, fresh);  // built aside: a throw changes nothing
  for (std::size_t i = 0; i < dirty.size(); ++i)
    std::swap(parts[static_cast<std::size_t>(dirty[i])], fresh[i]);
  return coords;
}

Mesh KeptChunks::chunk_mesh(Vec3i c, const char* who) const {
  for (int a = 0; a < 3; ++a)
    if (c[a] < 0 || c[a] >= grid.count[a])
      throw InvalidArgument(std::string(who) + "::chunk_mesh: chunk " + to_string(c) +
                            " is outside the " + to_string(grid.count) + " chunks");
  const ChunkPart& p = parts[static_cast<std::size_t>(
      c.x + static_cast<std::int64_t>(grid.count.x) *
                (c.y + static_cast<std::int64_t>(grid.count.y) * c.z))];
  Mesh m;
  m.positions = p.positions;
  m.normals = p.normals;
  m.colors = p.colors;
  m.indices = p.indices;
  return m;
}

Mesh KeptChunks::merged() const {
  return weld(parts, nullptr);
}

}  // namespace detail::mesh

struct MeshChunks::Impl {
  detail::mesh::KeptChunks kept;
  ScalarVolume frame;  // size, origin and spacing the chunks were meshed with
  // What the chunks were meshed from: a volume, or a terrain (with or without a palette). An
  // update must come from the same kind of source, so that every part has colours or none does.
  enum class Source { kVolume, kTerrain, kColouredTerrain } source = Source::kVolume;
  void check_source(Source given) const;
  void check_frame(const ScalarVolume& volume) const;
};

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
  impl_->kept.options = options;
  impl_->frame = volume;
  impl_->frame.values = nullptr;
  impl_->kept.mesh_all(lattice);
}

MeshChunks::MeshChunks(const TerrainField& terrain, const MeshOptions& options)
    : impl_(std::make_unique<Impl>()) {
  using namespace detail::mesh;
  impl_->kept.options = terrain_options(terrain, options);
  impl_->frame = terrain_frame(terrain);
  impl_->source =
      terrain.options().palette ? Impl::Source::kColouredTerrain : Impl::Source::kTerrain;
  TerrainSamples keep;
  impl_->kept.mesh_all(terrain_lattice(terrain, impl_->kept.options, keep));
}

std::vector<Vec3i> MeshChunks::update(const TerrainField& terrain, const Box3i& changed) {
  using namespace detail::mesh;
  impl_->check_source(terrain.options().palette ? Impl::Source::kColouredTerrain
                                                : Impl::Source::kTerrain);
  impl_->check_frame(terrain_frame(terrain));
  MeshOptions& options = impl_->kept.options;
  if (terrain_options(terrain, options).inside_above != options.inside_above)
    throw InvalidArgument("MeshChunks::update: the terrain's sign convention changed");
  TerrainSamples keep;
  return impl_->kept.update(terrain_lattice(terrain, options, keep), {changed});
}

MeshChunks::~MeshChunks() = default;
MeshChunks::MeshChunks(MeshChunks&&) noexcept = default;
MeshChunks& MeshChunks::operator=(MeshChunks&&) noexcept = default;

std::vector<Vec3i> MeshChunks::update(const ScalarVolume& volume, const Box3i& changed) {
  impl_->check_source(Impl::Source::kVolume);
  impl_->check_frame(volume);
  return impl_->kept.update(detail::mesh::checked_lattice(volume, impl_->kept.options, false),
                            {changed});
}

Vec3i MeshChunks::chunk_count() const {
  return impl_->kept.grid.count;
}

Mesh MeshChunks::chunk_mesh(Vec3i c) const {
  return impl_->kept.chunk_mesh(c, "MeshChunks");
}

Mesh MeshChunks::merged() const {
  return impl_->kept.merged();
}

}  // namespace voxfield
