// voxfield — one jump-flooding pass (Rong & Tan, I3D 2006; src/vectors/jfa.cpp's flood_pass on the
// GPU): each voxel keeps the best-scoring of its own source and those of its 26 neighbours at
// offsets of the pass's jump, reading one buffer and writing the other (never in place, which the
// paper's single-texture passes raced on). Ties go to the lower index, so the result does not
// depend on the order of the look-ups.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "vectors_common.glsl"

layout(local_size_x = 64) in;

void consider(int candidate, dvec3 p, inout int current, inout double current_score) {
  if (candidate < 0 || candidate == current) return;
  dvec3 q;
  const uint s = uint(candidate);
  const double sc = score(distance_to(s, p, q), radius_of(s));
  if (current < 0 || sc > current_score || (sc == current_score && candidate < current)) {
    current = candidate;
    current_score = sc;
  }
}

void voxel(uint i) {
  const ivec3 n = p.size.xyz;
  const ivec3 v = voxel_of(i);
  const dvec3 centre = voxel_centre(v);
  int best = winners_in[i];
  double best_score = 0.0LF;
  if (best >= 0) {
    dvec3 q;
    best_score = score(distance_to(uint(best), centre, q), radius_of(uint(best)));
  }
  const int step = p.pass.x;
  for (int dz = -step; dz <= step; dz += step) {
    const int kk = v.z + dz;
    if (kk < 0 || kk >= n.z) continue;
    for (int dy = -step; dy <= step; dy += step) {
      const int jj = v.y + dy;
      if (jj < 0 || jj >= n.y) continue;
      for (int dx = -step; dx <= step; dx += step) {
        const int ii = v.x + dx;
        if (ii < 0 || ii >= n.x || (dx == 0 && dy == 0 && dz == 0)) continue;
        consider(winners_in[ii + n.x * (jj + n.y * kk)], centre, best, best_score);
      }
    }
  }
  winners_out[i] = best;
}

void main() {
  const uint voxels = uint(p.size.x * p.size.y * p.size.z);
  for (uint i = gl_GlobalInvocationID.x; i < voxels; i += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    voxel(i);
}
