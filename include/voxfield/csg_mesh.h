// voxfield — meshes of CSG models: the model sampled on a lattice (through the voxel compiler's
// pruned evaluation) and meshed by marching cubes, surface nets or dual contouring, with normals
// and dual contouring's Hermite data from the model's own gradient, so that sharp edges and
// corners of boxes, cylinders and differences stay sharp; vertex colours from the paints.
#pragma once

#include <optional>

#include "voxfield/csg.h"
#include "voxfield/mesh.h"

namespace voxfield {

struct CsgMeshOptions {
  double voxel_size = 1;           // lattice spacing in model units
  std::optional<csg::Bounds> box;  // default: the model's bounds (required for unbounded models)
  MeshOptions mesh;                // algorithm, chunk edge, interrupter (iso and inside are fixed)
  // Crossings found on the model and normals from its gradient; false: the meshers' interpolation
  // and finite differences of the samples.
  bool exact_gradients = true;
  std::uint64_t memory_limit_bytes = 0;
};

// The surface of the model (value 0, inside below). The lattice covers the box grown by one
// spacing on every side, so the surface closes. Throws InvalidArgument / ResourceLimitError as
// voxelize() and mesh_volume() do.
Mesh mesh_csg(const csg::Model& model, const CsgMeshOptions& options);

}  // namespace voxfield
