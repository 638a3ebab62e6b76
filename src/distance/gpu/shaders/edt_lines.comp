// voxfield — later passes of the separable exact distance transform (Meijster, Roerdink &
// Hesselink 2000): along each line of the compute box (axis p.axis), the lower envelope of the
// functions f(x, i) = F(x - i, c(i)) over the line's voxels i, where c is the previous pass's cost:
//   Manhattan  F = |x - i| + c(i)
//   Chebyshev  F = max(|x - i|, c(i))
//   Euclidean  F = (x - i)^2 + c(i)      (c already squared)
// found by the forward scan that builds the envelope (Sep: where a later function starts to win)
// and the backward scan that reads it. Voxels with no site in reach (VF_INF) add no function.
// Where two functions tie, the earlier (smaller coordinate) keeps the voxel, as on the CPU; with
// nearest sites, each voxel takes the site of the function it took.
// One invocation per line; the s and t stacks live in this line's slice of the scratch buffers.
// Integer arithmetic only: with domain extents up to 16384, every value fits 31 bits.
#version 450
#include "common.glsl"

int f(int x, int i, int c) {
  const int d = abs(x - i);
  if (h.metric == VF_MANHATTAN) return d + c;
  if (h.metric == VF_CHEBYSHEV) return max(d, c);
  return d * d + c;
}

int floor_div(int a, int b) {  // b > 0
  return a >= 0 ? a / b : -((-a + b - 1) / b);
}

const int kPlusInf = 0x7FFFFFFF;
const int kMinusInf = -0x7FFFFFFF;

// The first x at which f(., u) is below f(., i), for i < u.
int sep(int i, int u, int ci, int cu) {
  if (h.metric == VF_MANHATTAN) {
    if (cu >= ci + (u - i)) return kPlusInf;
    if (ci > cu + (u - i)) return kMinusInf;
    return floor_div(cu - ci + u + i, 2);
  }
  if (h.metric == VF_CHEBYSHEV) {
    if (ci <= cu) return max(i + cu, floor_div(i + u, 2));
    return min(u - ci, floor_div(i + u, 2));
  }
  return floor_div(u * u - i * i + cu - ci, 2 * (u - i));
}

void main() {
  const uint line = invocation();
  const ivec3 n = p.box_size.xyz;
  const int len = n[p.axis];
  const int lines = (n.x * n.y * n.z) / len;
  if (int(line) >= lines) return;
  ivec3 first, step;
  line_of(line, first, step);
  const uint base = line * uint(len);  // this line's slice of the scratch buffers
  int q = -1;
  for (int u = 0; u < len; ++u) {
    const uint cu_raw = load_cost(p.src, voxel_index(first + step * u));
    if (cu_raw == VF_INF) continue;
    const int cu = int(cu_raw);
    while (q >= 0) {
      const int sq = scratch_s[base + uint(q)], tq = scratch_t[base + uint(q)];
      const int cs = int(load_cost(p.src, voxel_index(first + step * sq)));
      if (f(tq, sq, cs) > f(tq, u, cu)) --q; else break;
    }
    if (q < 0) {
      q = 0;
      scratch_s[base] = u;
      scratch_t[base] = 0;
    } else {
      const int sq = scratch_s[base + uint(q)];
      const int cs = int(load_cost(p.src, voxel_index(first + step * sq)));
      const int s = sep(sq, u, cs, cu);
      const int w = s >= kPlusInf - 1 ? kPlusInf : s + 1;
      if (w < len) {
        ++q;
        scratch_s[base + uint(q)] = u;
        scratch_t[base + uint(q)] = max(w, 0);
      }
    }
  }
  for (int u = len - 1; u >= 0; --u) {
    const uint i = voxel_index(first + step * u);
    if (q < 0) {
      store_cost(p.dst, i, VF_INF);
      if (h.track_sites != 0u) store_site(p.dst, i, uvec2(VF_INF, 0u));
      continue;
    }
    const int sq = scratch_s[base + uint(q)];
    const uint source = voxel_index(first + step * sq);
    const int cs = int(load_cost(p.src, source));
    store_cost(p.dst, i, uint(f(u, sq, cs)));
    if (h.track_sites != 0u) store_site(p.dst, i, load_site(p.src, source));
    if (u == scratch_t[base + uint(q)]) --q;
  }
}
