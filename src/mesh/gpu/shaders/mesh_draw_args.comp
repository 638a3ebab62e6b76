// voxfield — the terrain drawn from its HistoPyramid: the indirect draw's arguments from the
// pyramid's top (three vertices per triangle, one instance), so the frame's vertex count never
// travels through the host.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "mesh_common.glsl"

layout(std430, set = 0, binding = 4) readonly buffer Pyramid { uint pyramid[]; };
// A VkDrawIndirectCommand: vertexCount, instanceCount, firstVertex, firstInstance.
layout(std430, set = 0, binding = 9) writeonly buffer Draw { uvec4 draw; };

layout(local_size_x = 1) in;

void main() {
  draw = uvec4(3u * pyramid[uint(levels[p.pass.y - 1].x)], 1u, 0u, 0u);
}
