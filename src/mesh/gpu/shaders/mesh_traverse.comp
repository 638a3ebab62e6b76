// voxfield — marching cubes on the GPU, pass 4: HistoPyramid traversal (Dyken et al. 2007), one
// invocation per output triangle: from the pyramid's top down, the triangle's index picks the
// child whose range holds it, to a cell and a triangle of its case; the triangle's three vertices
// are then computed as src/mesh/marching_cubes.cpp computes them (mesh_walk.glsl) and written in
// order, so the triangles are the CPU's and wind the same way.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "mesh_walk.glsl"

layout(std430, set = 0, binding = 6) writeonly buffer Vertices { float vertices[]; };
layout(std430, set = 0, binding = 7) readonly buffer Args { uvec4 args; };
// Per vertex its lattice element, for the host to share vertices as the CPU mesher does.
layout(std430, set = 0, binding = 8) writeonly buffer Keys { uvec2 keys[]; };

layout(local_size_x = 64) in;

void triangle(uint k) {
  uint index, key;
  walk(k, index, key);
  for (uint v = 0u; v < 3u; ++v) {
    vec3 pos, nrm;
    uvec2 element;
    uint source;
    triangle_vertex(index, key, v, pos, nrm, element, source);
    const uint base = (3u * k + v) * uint(VF_MC_VERTEX_FLOATS);
    vertices[base] = pos.x;
    vertices[base + 1u] = pos.y;
    vertices[base + 2u] = pos.z;
    vertices[base + 3u] = nrm.x;
    vertices[base + 4u] = nrm.y;
    vertices[base + 5u] = nrm.z;
    keys[3u * k + v] = element;
  }
}

void main() {
  const uint drawn = min(args.w, uint(p.pass.z));
  for (uint k = gl_GlobalInvocationID.x; k < drawn; k += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    triangle(k);
}
