// voxfield — meshing a terrain field (terrain.h): the chunked meshers read its quantised chunks
// through the lattice's fill (each chunk's block decodes what it reads, so no dense copy of the
// field is ever made) and colour vertices by the material of the inside sample they come from.
#include "mesh_internal.h"
#include "voxfield/terrain.h"

namespace voxfield {

namespace detail::mesh {

ScalarVolume terrain_frame(const TerrainField& terrain) {
  const TerrainOptions& o = terrain.options();
  ScalarVolume v;
  v.size = o.samples;
  v.origin_units = o.origin_units;
  v.spacing_units = {o.spacing_units, o.spacing_units, o.spacing_units};
  return v;
}

MeshOptions terrain_options(const TerrainField& terrain, const MeshOptions& options) {
  MeshOptions o = options;
  o.iso = 0;
  // decode() gives the field's convention: inside is above 0 when it is positive inside (the
  // meshes are the same: the mesher negates those values back, exactly).
  o.inside_above = terrain.options().positive_inside;
  return o;
}

Lattice terrain_lattice(const TerrainField& terrain, const MeshOptions& terrain_options,
                        TerrainSamples& keep) {
  keep.fill = [&terrain](const Box3i& region, float* out) { terrain.decode(region, out); };
  keep.color = nullptr;
  if (terrain.options().palette) {
    const Vec3i n = terrain.size();
    keep.color = [&terrain, n](std::uint64_t index) {
      const auto nx = static_cast<std::uint64_t>(n.x), ny = static_cast<std::uint64_t>(n.y);
      const Vec3i p{static_cast<int>(index % nx), static_cast<int>(index / nx % ny),
                    static_cast<int>(index / nx / ny)};
      const Rgba c = (*terrain.options().palette)[terrain.material(p)];
      return std::array<std::uint8_t, 3>{c.r, c.g, c.b};
    };
  }
  Lattice lattice = checked_lattice(terrain_frame(terrain), terrain_options, false, &keep.fill);
  lattice.color = keep.color ? &keep.color : nullptr;
  return lattice;
}

}  // namespace detail::mesh

Mesh mesh_terrain(const TerrainField& terrain, const MeshOptions& options) {
  using namespace detail::mesh;
  const MeshOptions o = terrain_options(terrain, options);
  TerrainSamples keep;
  return weld(mesh_all_chunks(terrain_lattice(terrain, o, keep), o), nullptr);
}

}  // namespace voxfield
