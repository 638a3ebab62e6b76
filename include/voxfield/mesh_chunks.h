// voxfield — a volume's mesh kept chunk by chunk and re-meshed only where its samples change: the
// deformable-terrain case (Nässén & Leiborn re-sent their whole field every frame and named
// "update only the chunks that changed" as future work).
//
// Each chunk's mesh is a unit a renderer uploads and swaps on its own: its triangles over its own
// vertices, the vertices on its borders repeated in its neighbours' meshes with bit-identical
// positions (no cracks between separately drawn chunks). merged() welds them into exactly the
// mesh a new MeshChunks gives for the same samples, and the same triangles (positions and normals
// bit for bit) as mesh_volume(), which numbers its vertices by row: updating is never an
// approximation.
#pragma once

#include <memory>
#include <vector>

#include "voxfield/mesh.h"

namespace voxfield {

class TerrainField;

class MeshChunks {
 public:
  // Meshes every chunk of `volume` (options as for mesh_volume; the same errors). The
  // interrupter, if any, watches this first mesh only.
  MeshChunks(const ScalarVolume& volume, const MeshOptions& options);
  ~MeshChunks();
  MeshChunks(MeshChunks&&) noexcept;
  MeshChunks& operator=(MeshChunks&&) noexcept;

  // The samples in `changed` (sample coordinates; clipped to the volume) were rewritten: re-meshes
  // every chunk whose triangles read one of them and returns those chunks. `volume` is the same
  // volume (its buffer may have moved; its size and frame must not change: InvalidArgument). Each
  // chunk's new mesh is built aside and replaces its old one whole, after all of them are built,
  // so an exception (NaN sample, cancellation) leaves every chunk as it was.
  std::vector<Vec3i> update(const ScalarVolume& volume, const Box3i& changed);

  // A terrain field's chunks: merged() equals mesh_terrain(terrain, options), colours included.
  MeshChunks(const TerrainField& terrain, const MeshOptions& options);
  // After edits of the same terrain (a copy of it will do): `changed` as TerrainField::apply
  // returns it (or the union of several). InvalidArgument when its size or frame changed.
  std::vector<Vec3i> update(const TerrainField& terrain, const Box3i& changed);

  Vec3i chunk_count() const;
  // Chunk `c`'s own mesh (colours for a terrain with a palette). InvalidArgument for a chunk
  // outside chunk_count().
  Mesh chunk_mesh(Vec3i c) const;
  // All chunks welded: equal, array for array, to MeshChunks(volume, options).merged() now, and
  // triangle for triangle to mesh_volume(volume, options).
  Mesh merged() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxfield
