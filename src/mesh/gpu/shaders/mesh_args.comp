// voxfield — marching cubes on the GPU, pass 3: the traversal's indirect dispatch from the
// pyramid's top (the number of triangles), clamped to the vertex buffer's capacity; nothing is
// read back to size it.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "mesh_common.glsl"

layout(std430, set = 0, binding = 4) readonly buffer Pyramid { uint pyramid[]; };
// x, y, z: workgroups of the traversal; w: the triangles the pyramid counts.
layout(std430, set = 0, binding = 7) writeonly buffer Args { uvec4 args; };

layout(local_size_x = 1) in;

void main() {
  const uint total = pyramid[uint(levels[p.pass.y - 1].x)];
  const uint drawn = min(total, uint(p.pass.z));
  // At most the device's x limit of workgroups (p.pass.w): the traversal strides over the rest.
  args = uvec4(min((drawn + 63u) / 64u, uint(p.pass.w)), 1u, 1u, total);
}
