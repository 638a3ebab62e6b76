// voxfield — the terrain's pixels: the CPU rasteriser's shading (src/render/mesh_raster.cpp), one
// directional light (Lambert) plus ambient, the normal turned towards the viewer so both faces are
// lit, times the interpolated vertex colour.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(std430, set = 0, binding = 6) readonly buffer View { MeshDrawView view; };

layout(location = 0) in vec3 world;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour;
layout(location = 0) out vec4 pixel;

void main() {
  const float length_n = length(normal);
  vec3 n = length_n > 0.0 ? normal / length_n : vec3(0.0, 0.0, 1.0);
  const vec3 ray = view.eye.w > 0.5 ? world - view.eye.xyz : view.forward.xyz;
  if (dot(n, ray) > 0.0) n = -n;
  const float shade = 0.28 + 0.72 * max(0.0, dot(n, view.light.xyz));
  pixel = vec4(min(colour * shade, vec3(255.0)) / 255.0, 1.0);
}
