// voxfield render — what both halves of the CSG renderer share (csg_render.cpp on the CPU,
// gpu/gpu_csg_render.cpp on Vulkan): the traced box, the octree, the camera and the surface
// epsilon of a frame, and the colours of the variants view, so that both draw the same cells.
#pragma once

#include <optional>

#include "shading.h"
#include "voxfield/csg_compile.h"
#include "voxfield/csg_render.h"

namespace voxfield::render_detail {

struct CsgFrame {
  csg::Tape whole;
  std::optional<csg::Octree> tree;  // without pruning: none, the whole tape through the box
  csg::Bounds traced_box;           // the octree's root, or the model's box
  Camera camera;
  double epsilon = 0;  // a hit is a value below it (model units)
  double octree_ms = 0;
};
// Throws as render_csg does (an unbounded model without a box; Cancelled).
CsgFrame prepare_csg_frame(const csg::Model& model, const CsgRenderOptions& options);

// A colour per variant, well apart in hue (golden-ratio steps).
Rgb variant_colour(int variant);

}  // namespace voxfield::render_detail
