// voxfield — marching cubes on the GPU, pass 4: HistoPyramid traversal (Dyken et al. 2007), one
// invocation per output triangle: from the pyramid's top down, the triangle's index picks the
// child whose range holds it, to a cell and a triangle of its case; the triangle's three vertices
// are then computed as src/mesh/marching_cubes.cpp computes them — the crossing on the edge, the
// position in the volume's frame, the normal blended from the central-difference gradients at the
// edge's ends, a centre vertex the mean of its loop's crossings — and written in order, so the
// triangles are the CPU's and wind the same way.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "mesh_common.glsl"

layout(std430, set = 0, binding = 4) readonly buffer Pyramid { uint pyramid[]; };
layout(std430, set = 0, binding = 5) readonly buffer Cases { uint cell_case[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Vertices { float vertices[]; };
layout(std430, set = 0, binding = 7) readonly buffer Args { uvec4 args; };
// Per vertex its lattice element, for the host to share vertices as the CPU mesher does: (3 x the
// edge's lower sample + its axis, 0) for a crossing, (2 x the cell + the loop, 1) for a centre.
layout(std430, set = 0, binding = 8) writeonly buffer Keys { uvec2 keys[]; };

layout(local_size_x = 64) in;

// Block::gradient: central differences, one-sided on the lattice's faces, per unit.
dvec3 gradient(ivec3 v) {
  dvec3 g;
  for (int a = 0; a < 3; ++a) {
    ivec3 lo = v, hi = v;
    if (v[a] > 0) --lo[a];
    if (v[a] < p.size[a] - 1) ++hi[a];
    precise double span = double(hi[a] - lo[a]) * frame[1][a];
    precise double d = (double(s_at(hi)) - double(s_at(lo))) / span;
    g[a] = d;
  }
  return g;
}

// ChunkPart::add: the normal normalised in double (a zero or non-finite length gives +z), then
// position and normal rounded to float.
void emit(dvec3 position, dvec3 normal, out vec3 pos, out vec3 nrm) {
  precise double length2 = normal.x * normal.x + normal.y * normal.y;
  precise double length2z = length2 + normal.z * normal.z;
  precise double length = sqrt(length2z);
  dvec3 n = dvec3(0.0LF, 0.0LF, 1.0LF);
  if (length > 0.0LF && !isinf(length) && !isnan(length)) {
    precise dvec3 scaled = dvec3(normal.x / length, normal.y / length, normal.z / length);
    n = scaled;
  }
  pos = vec3(position);
  nrm = vec3(n);
}

// The vertex on cube edge `edge` of the cell at `cell`.
void edge_vertex(ivec3 cell, uint edge, out vec3 pos, out vec3 nrm) {
  const uint from = tables[VF_MC_EDGES + 2 * int(edge)];
  const int axis = int(tables[VF_MC_EDGES + 2 * int(edge) + 1]);
  const ivec3 lo = cell + corner_offset(from);
  ivec3 hi = lo;
  ++hi[axis];
  const double s0 = double(s_at(lo)), s1 = double(s_at(hi));
  precise double t = s0 / (s0 - s1);
  dvec3 at = dvec3(lo);
  precise double moved = at[axis] + t;
  at[axis] = moved;
  precise dvec3 position = dvec3(frame[0].x + at.x * frame[1].x, frame[0].y + at.y * frame[1].y,
                                 frame[0].z + at.z * frame[1].z);
  const dvec3 g0 = gradient(lo), g1 = gradient(hi);
  precise dvec3 normal = dvec3(g0.x + t * (g1.x - g0.x), g0.y + t * (g1.y - g0.y),
                               g0.z + t * (g1.z - g0.z));
  if (normal.x == 0.0LF && normal.y == 0.0LF && normal.z == 0.0LF) {
    normal = dvec3(0.0LF);
    normal[axis] = s0 < 0.0LF ? 1.0LF : -1.0LF;
  }
  emit(position, normal, pos, nrm);
}

void triangle(uint k) {
  // Down the pyramid: at each level, the child whose running count passes k.
  uint key = k, index = 0u;
  const int top = p.pass.y - 1;
  for (int l = top - 1; l >= 0; --l) {
    const ivec4 lv = levels[l];
    const ivec4 up = levels[l + 1];
    uint chosen = 0u;
    if (p.cells.w == VF_MC_PYRAMID_4) {
      for (uint j = 0u; j < 4u; ++j) {
        const uint child = 4u * index + j;
        if (child >= uint(lv.y)) break;
        const uint n = pyramid[uint(lv.x) + child];
        chosen = child;
        if (key < n) break;
        key -= n;
      }
    } else {
      const ivec3 at = ivec3(int(index % uint(up.y)), int((index / uint(up.y)) % uint(up.z)),
                             int(index / uint(up.y * up.z)));
      for (uint c = 0u; c < 8u; ++c) {
        const ivec3 child = 2 * at + corner_offset(c);
        if (child.x >= lv.y || child.y >= lv.z || child.z >= lv.w) continue;
        const uint linear = uint(child.x + lv.y * (child.y + lv.z * child.z));
        const uint n = pyramid[uint(lv.x) + linear];
        chosen = linear;
        if (key < n) break;
        key -= n;
      }
    }
    index = chosen;
  }
  // index: the cell; key: its triangle.
  const ivec3 cell = cell_of(index);
  const uint record = uint(VF_MC_CASES) + uint(VF_MC_CASE_WORDS) * cell_case[index];
  vec3 pos[3], nrm[3];
  uvec2 element[3];
  for (uint v = 0u; v < 3u; ++v) {
    const uint edge = tables[record + 1u + 3u * key + v];
    if (edge < uint(VF_MC_CENTRE)) {
      edge_vertex(cell, edge, pos[v], nrm[v]);
      const uint from = tables[VF_MC_EDGES + 2 * int(edge)];
      const uint axis = tables[VF_MC_EDGES + 2 * int(edge) + 1];
      element[v] = uvec2(3u * sample_index(cell + corner_offset(from)) + axis, 0u);
      continue;
    }
    // A centre vertex: the mean of its loop's crossings (float positions over the loop's length,
    // summed in the loop's order) and the sum of their normals.
    const uint c = edge - uint(VF_MC_CENTRE);
    const uint n = tables[record + 38u + c];
    dvec3 mean = dvec3(0.0LF), normal = dvec3(0.0LF);
    for (uint i = 0u; i < n; ++i) {
      vec3 q, m;
      edge_vertex(cell, tables[record + 40u + 12u * c + i], q, m);
      precise dvec3 next_mean = dvec3(mean.x + double(q.x) / double(n), mean.y + double(q.y) / double(n),
                                      mean.z + double(q.z) / double(n));
      precise dvec3 next_normal = dvec3(normal.x + double(m.x), normal.y + double(m.y),
                                        normal.z + double(m.z));
      mean = next_mean;
      normal = next_normal;
    }
    emit(mean, normal, pos[v], nrm[v]);
    element[v] = uvec2(2u * index + c, 1u);
  }
  for (uint v = 0u; v < 3u; ++v) {
    const uint base = (3u * k + v) * uint(VF_MC_VERTEX_FLOATS);
    vertices[base] = pos[v].x;
    vertices[base + 1u] = pos[v].y;
    vertices[base + 2u] = pos[v].z;
    vertices[base + 3u] = nrm[v].x;
    vertices[base + 4u] = nrm[v].y;
    vertices[base + 5u] = nrm[v].z;
    keys[3u * k + v] = element[v];
  }
}

void main() {
  const uint drawn = min(args.w, uint(p.pass.z));
  for (uint k = gl_GlobalInvocationID.x; k < drawn; k += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    triangle(k);
}
