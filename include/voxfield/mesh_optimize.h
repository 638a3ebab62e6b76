// voxfield — making meshes lighter and faster to draw, with meshoptimizer (Debian
// libmeshoptimizer-dev 0.18, by Arseny Kapoulkine: the reference implementation games use).
//
// simplify_mesh collapses edges by quadric error (Garland & Heckbert, "Surface Simplification
// Using Quadric Error Metrics", SIGGRAPH 1997) down to a triangle budget or an error limit,
// keeping the mesh's open borders in place (so chunks simplified apart still meet);
// optimize_mesh reorders triangles for the GPU's post-transform vertex cache and vertices for
// fetch locality. Both keep normals and colours with their vertices and drop unreferenced ones.
#pragma once

#include "voxfield/mesh.h"

namespace voxfield {

struct SimplifyOptions {
  // Keep about this fraction of the triangles (0 <= ratio <= 1; 0: as few as the error limit
  // allows)...
  double triangle_ratio = 0.5;
  // ...unless that moves the surface farther than this, in the mesh's units (0: the default,
  // 1 % of the mesh's largest extent).
  double max_error_units = 0;
};

struct SimplifyStats {
  std::size_t triangles_before = 0, triangles_after = 0;
  double error_units = 0;  // the largest deviation meshoptimizer estimates, in the mesh's units
};

// Throws InvalidArgument for a ratio outside [0, 1], a negative error or arrays that disagree.
Mesh simplify_mesh(const Mesh& mesh, const SimplifyOptions& options,
                   SimplifyStats* stats = nullptr);
void optimize_mesh(Mesh& mesh);

}  // namespace voxfield
