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
#include <optional>
#include <vector>

#include "voxfield/edit.h"
#include "voxfield/mesh.h"

namespace voxfield {

class TerrainField;
struct DistanceField;

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

// A voxel world's surface kept chunk by chunk through its edits: what mesh_world() gives, re-meshed
// only where edits reach. It keeps what that surface is made from — the world's exact signed
// field, clamped at |iso| + 3 voxels (a DynamicDistanceField, bit for bit a full rebuild after
// every update) — over a fixed lattice: the world's bounds (or a box) grown by the air
// mesh_world() puts around the content, so the surface closes at the bounds as it does there.
// Because that field reaches past the bounds, where the world stores nothing, it is computed on a
// copy of the world's voxels without bounds, refreshed in the boxes the edits changed (one byte per
// stored voxel; uniform chunks cost nothing).
//
// merged() has the same triangles as mesh_world(world, options, metric) for the edited world —
// positions, normals and colours (at iso 0 bit for bit; offset surfaces within float rounding of
// the lattice's other origin) — and an edit re-meshes the chunks within |iso| + 6 samples of
// what it changed. Chunk meshes are in voxel coordinates placed in the world's frame, as
// mesh_world()'s.
class WorldMeshChunks {
 public:
  // Binds to `world` (which must outlive this object) and meshes the voxels inside `box` — by
  // default the world's bounds; for an unbounded world the box must be given (InvalidArgument
  // otherwise: the lattice must stay fixed), and voxels outside it are taken for air (merged()
  // is then mesh_world() of the world cut to the box; edits outside it change nothing). A box
  // reaching past a bounded world's bounds is cut to them. Errors as mesh_world()'s (iso out of
  // range, the memory limit, Cancelled through options.interrupter, which watches this first mesh
  // only); InvalidArgument for an empty box.
  WorldMeshChunks(const World& world, const MeshOptions& options,
                  Metric metric = Metric::kEuclidean, std::optional<Box3i> box = std::nullopt);
  ~WorldMeshChunks();
  WorldMeshChunks(WorldMeshChunks&&) noexcept;
  WorldMeshChunks& operator=(WorldMeshChunks&&) noexcept;

  // After edits of the world recorded in `dirty` — with DirtyRegions::Track::kAnyChange, so that
  // a repaint, which changes no distance, re-colours its chunks — updates the field and re-meshes
  // the chunks the changes reach; returns those chunks. The caller clears `dirty` afterwards.
  // InvalidArgument when the world's bounds changed or `dirty` tracks occupancy only. Each chunk's
  // new mesh is built aside and replaces its old one whole, after all of them are built; but the
  // field is written region by region (DynamicDistanceField::update), so after an exception the
  // chunks are the old ones and the field part new: call rebuild().
  std::vector<Vec3i> update(const DirtyRegions& dirty);
  // Copies the world again, recomputes the field and re-meshes every chunk (after a palette
  // change, or an exception in update()).
  void rebuild();

  Vec3i chunk_count() const;
  // Chunk `c`'s own mesh. InvalidArgument for a chunk outside chunk_count().
  Mesh chunk_mesh(Vec3i c) const;
  // All chunks welded.
  Mesh merged() const;
  // The signed field the surface is meshed from (over the lattice's voxels).
  const DistanceField& field() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxfield
