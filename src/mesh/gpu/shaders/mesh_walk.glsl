// voxfield shaders — the HistoPyramid walk and a triangle's vertices (src/mesh/gpu), shared by the
// traversal that writes a vertex buffer (mesh_traverse.comp) and the vertex shader that draws
// from the pyramid by gl_VertexIndex (mesh_draw.vert): Dyken, Ziegler, Theobalt & Seidel, "High-
// speed Marching Cubes using HistoPyramids" (2007). A vertex is computed as
// src/mesh/marching_cubes.cpp computes it — the crossing on the edge, the position in the volume's
// frame, the normal blended from the central-difference gradients at the edge's ends, a centre
// vertex the mean of its loop's crossings — with every intermediate `precise`, so the traversal
// gives the CPU's triangles bit for bit.
#extension GL_GOOGLE_include_directive : require
#include "mesh_common.glsl"

layout(std430, set = 0, binding = 4) readonly buffer Pyramid { uint pyramid[]; };
layout(std430, set = 0, binding = 5) readonly buffer Cases { uint cell_case[]; };

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
    precise double inverse = 1.0LF / length;
    precise dvec3 scaled = dvec3(normal.x * inverse, normal.y * inverse, normal.z * inverse);
    n = scaled;
  }
  pos = vec3(position);
  nrm = vec3(n);
}

// The vertex on cube edge `edge` of the cell at `cell`, and the inside sample it comes from (the
// CPU colours a vertex by that sample's material).
void edge_vertex(ivec3 cell, uint edge, out vec3 pos, out vec3 nrm, out uint source) {
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
  source = s0 < 0.0LF ? sample_index(lo) : sample_index(hi);
}

// Down the pyramid from its top: at each level, the child whose running count passes k. Gives
// the cell (its linear index) and which of its case's triangles k is.
void walk(uint k, out uint index, out uint key) {
  key = k;
  index = 0u;
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
}

// Vertex v (0..2) of triangle `key` of cell `index`: its position and normal, its lattice element
// ((3 x the edge's lower sample + its axis, 0) for a crossing, (2 x the cell + the loop, 1) for a
// centre) and its source sample (a centre's is its loop's first crossing's, as on the CPU).
void triangle_vertex(uint index, uint key, uint v, out vec3 pos, out vec3 nrm, out uvec2 element,
                     out uint source) {
  const ivec3 cell = cell_of(index);
  const uint record = uint(VF_MC_CASES) + uint(VF_MC_CASE_WORDS) * cell_case[index];
  const uint edge = tables[record + 1u + 3u * key + v];
  if (edge < uint(VF_MC_CENTRE)) {
    edge_vertex(cell, edge, pos, nrm, source);
    const uint from = tables[VF_MC_EDGES + 2 * int(edge)];
    const uint axis = tables[VF_MC_EDGES + 2 * int(edge) + 1];
    element = uvec2(3u * sample_index(cell + corner_offset(from)) + axis, 0u);
    return;
  }
  // A centre vertex: the mean of its loop's crossings (float positions over the loop's length,
  // summed in the loop's order) and the sum of their normals.
  const uint c = edge - uint(VF_MC_CENTRE);
  const uint n = tables[record + 38u + c];
  dvec3 mean = dvec3(0.0LF), normal = dvec3(0.0LF);
  for (uint i = 0u; i < n; ++i) {
    vec3 q, m;
    uint from_sample;
    edge_vertex(cell, tables[record + 40u + 12u * c + i], q, m, from_sample);
    if (i == 0u) source = from_sample;
    precise dvec3 next_mean = dvec3(mean.x + double(q.x) / double(n), mean.y + double(q.y) / double(n),
                                    mean.z + double(q.z) / double(n));
    precise dvec3 next_normal = dvec3(normal.x + double(m.x), normal.y + double(m.y),
                                      normal.z + double(m.z));
    mean = next_mean;
    normal = next_normal;
  }
  emit(mean, normal, pos, nrm);
  element = uvec2(2u * index + c, 1u);
}
