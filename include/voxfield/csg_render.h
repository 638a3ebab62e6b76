// voxfield — pictures of CSG models: sphere tracing through the compiler's octree, each cell with
// its own pruned tape, cells visited front to back along every ray so that empty and hidden cells
// cost nothing; a view colouring each cell by its variant (Palecek's gear picture). Shading is the
// voxel renderer's (palette albedo in linear light, sun, sky dome, exposure).
#pragma once

#include <cstdint>
#include <optional>

#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"
#include "voxfield/image.h"
#include "voxfield/interrupt.h"
#include "voxfield/render.h"

namespace voxfield {

struct CsgRenderOptions {
  int width = 640, height = 480;
  std::optional<Camera> camera;  // default: csg_camera(bounds, aspect)
  enum class View { kShaded, kVariants };
  View view = View::kShaded;
  bool prune = true;  // false: trace the whole tape through the model's box (for comparison)
  int depth = 6;      // of the octree
  bool shadows = true;
  std::optional<csg::Bounds>
      box;  // the box traced (default: the model's bounds); needed when unbounded
  Interrupter* interrupter = nullptr;
};

struct CsgRenderStats {
  double octree_ms = 0, render_ms = 0;
  std::int64_t rays = 0, hits = 0;
  std::int64_t evaluations = 0;    // tape evaluations at a point
  std::int64_t instructions = 0;   // instructions those evaluations ran
  std::int64_t cells_entered = 0;  // surface cells a ray marched in
  int variants = 0;
};

// A perspective view of the box from above one corner (the voxel renderer's framing direction).
Camera csg_camera(const csg::Bounds& box, double aspect);

// Throws InvalidArgument for an unbounded model without a box, Cancelled when interrupted.
Image render_csg(const csg::Model& model, const CsgRenderOptions& options,
                 CsgRenderStats* stats = nullptr);

}  // namespace voxfield
