// voxfield — marching cubes on the GPU (Vulkan compute), the reference thesis's pipeline (Nässén &
// Leiborn, "Real-time Terrain Deformation with Isosurface Algorithms", 2019, after Dyken, Ziegler,
// Theobalt & Seidel, "High-speed Marching Cubes using HistoPyramids", 2007):
//  1. classify: each cell's corner mask, its ambiguous faces settled by the asymptotic decider as
//     the CPU settles them, its triangle count (the pyramid's base) and its case;
//  2. a HistoPyramid built level by level: 4-to-1 over the cells' linear order (the thesis's), or
//     the 3-D 8-to-1 variant;
//  3. the traversal's indirect dispatch from the pyramid's top, clamped to the vertex buffer's
//     capacity (nothing read back to size it);
//  4. traversal by output index: each invocation walks the pyramid down to its cell and triangle
//     and writes the triangle's three vertices (position and normal).
// The triangles are the CPU marching cubes' (mesh.h): the same case table, the same decisions, the
// same crossing and normal arithmetic in doubles — bit for bit on lavapipe (tests/
// test_gpu_mesh.cpp); each vertex carries its lattice element, by which the host shares vertices
// as the CPU mesher does.
#pragma once

#include <cstdint>
#include <string>

#include "voxfield/gpu.h"
#include "voxfield/mesh.h"
#include "voxfield/terrain.h"

namespace voxfield::gpu {

enum class Pyramid : std::uint8_t { kFourToOne, kEightToOne };

struct GpuMeshOptions {
  Pyramid pyramid = Pyramid::kFourToOne;
  // The most triangles meshed (72 bytes each of positions and normals, 24 of vertex elements; the
  // buffers are allocated at the surface's own count); 0: as many as one storage buffer of the
  // device holds. More triangles than this: ResourceLimitError naming both counts.
  std::uint64_t max_triangles = 0;
};

struct GpuMeshStats {
  std::int64_t dispatches = 0, submits = 0, fence_waits = 0;
  std::int64_t bytes_uploaded = 0, bytes_downloaded = 0;
  std::int64_t samples_bytes = 0;  // of the upload: the field's samples in their width
  int pyramid_levels = 0;
  std::uint64_t triangles = 0;
  std::string field_width;  // "f32", "i16" (two per word) or "i8" (four per word)
  double ms = 0;            // wall time of the call
};

// Marching cubes of `volume` at options.iso (options.inside_above honoured; chunk_edge is not
// used): the triangles of mesh_volume() with Mesher::kMarchingCubes, with normals and no colours,
// indexed with the same vertices shared (each vertex is its lattice edge's, or its cell's centre;
// the order of triangles and vertices is the pyramid's, not the CPU's). Throws
// InvalidArgument as mesh_volume does, and for options.gradient or options.value (evaluated on
// the CPU only); GpuUnavailable without a device with shaderFloat64; ResourceLimitError for a
// volume past one storage buffer or more triangles than the vertex buffer holds.
Mesh marching_cubes(Context& context, const ScalarVolume& volume, const MeshOptions& options,
                    const GpuMeshOptions& gpu = {}, GpuMeshStats* stats = nullptr);

// The terrain field's surface, its samples uploaded in their own width — i8 four per word
// (unpacked with bitfieldExtract, as the thesis's chars), i16 two per word, or f32 — and decoded
// on the device as the CPU decodes them: the triangles of mesh_terrain() with marching cubes.
Mesh marching_cubes(Context& context, const TerrainField& terrain, const GpuMeshOptions& gpu = {},
                    GpuMeshStats* stats = nullptr);

}  // namespace voxfield::gpu
