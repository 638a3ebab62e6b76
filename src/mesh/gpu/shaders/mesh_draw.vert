// voxfield — the terrain drawn from its HistoPyramid, the reference thesis's way (Nässén &
// Leiborn 2019, after Dyken et al. 2007): no vertex buffer; vertex gl_VertexIndex walks the
// pyramid to its cell and triangle (mesh_walk.glsl) and computes its position, normal and the
// material colour of the sample it comes from — the CPU marching cubes' vertex. Projection as the
// CPU rasteriser's camera (src/render/mesh_raster.cpp), with reversed depth (near / view depth:
// a float depth buffer keeps its precision far away).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "mesh_walk.glsl"

layout(std430, set = 0, binding = 6) readonly buffer View { MeshDrawView view; };
// The samples' materials, one byte each packed four per word as the i8 samples; the palette's
// 256 colours as packed RGBA8 (red in the low byte).
layout(std430, set = 0, binding = 7) readonly buffer Materials { uint materials[]; };
layout(std430, set = 0, binding = 8) readonly buffer Palette { uint palette[]; };

layout(location = 0) out vec3 world;
layout(location = 1) out vec3 normal;
layout(location = 2) out vec3 colour;

void main() {
  const uint k = uint(gl_VertexIndex) / 3u, v = uint(gl_VertexIndex) % 3u;
  uint index, key;
  walk(k, index, key);
  vec3 pos, nrm;
  uvec2 element;
  uint source;
  triangle_vertex(index, key, v, pos, nrm, element, source);
  world = pos;
  normal = nrm;
  if (view.light.w > 0.5) {
    const uint material = bitfieldExtract(materials[source >> 2u], int((source & 3u) * 8u), 8);
    colour = vec3(unpackUnorm4x8(palette[material]).rgb) * 255.0;
  } else {
    colour = view.base.rgb;
  }
  const vec3 d = pos - view.eye.xyz;
  const float x = dot(d, view.right.xyz), y = dot(d, view.up.xyz), z = dot(d, view.forward.xyz);
  const float scale = view.right.w, aspect = view.up.w;
  if (view.eye.w > 0.5) {
    // Clip w = view depth: x / z and y / z are the CPU's screen coordinates; depth near / z.
    gl_Position = vec4(x / scale * aspect, -y / scale, view.forward.w, z);
  } else {
    const float range = max(view.depth.y - view.depth.x, 1e-30);
    gl_Position = vec4(x / scale * aspect, -y / scale, clamp((view.depth.y - z) / range, 0.0, 1.0),
                       1.0);
  }
}
