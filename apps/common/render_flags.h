// voxfield and voxfield-mpi — the flags their render commands share (--width, --height, --view,
// --metric, --skip, --no-shadows, --no-ao, --fog) and the options they make, so that the same
// command line draws the same frame in both programs.
#pragma once

#include <string>

#include "voxfield/render.h"

namespace voxfield::apps {

struct RenderFlags {
  int width = 1280, height = 720;
  std::string view = "shaded", metric = "manhattan", skip = "distance";
  bool no_shadows = false, no_ao = false;
  double fog = 0;

  // The scene's fields: the skip field's metric, and the lighting field when anything reads it.
  RenderSceneOptions scene_options() const {
    RenderSceneOptions so;
    so.skip_metric = parse_metric(metric);
    so.lighting_field = !(no_shadows && no_ao);
    return so;
  }
  RenderOptions frame_options() const {
    RenderOptions o;
    o.width = width;
    o.height = height;
    o.view = parse_render_view(view);
    o.skip = parse_skip_mode(skip);
    o.soft_shadows = !no_shadows;
    o.ambient_occlusion = !no_ao;
    o.fog_density = fog;
    return o;
  }
};

}  // namespace voxfield::apps
