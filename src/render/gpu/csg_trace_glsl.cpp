// voxfield render — the Vulkan CSG renderer's kernels (see gpu_csg_render.cpp for the schedule).
//
// Wavefront sphere tracing (Laine, Karras and Aila, "Megakernels Considered Harmful: Wavefront
// Path Tracing on GPUs", 2013) over the voxel compiler's octree (Palecek, "A Better Approach to
// SDF Decomposition", 2022): each round moves every active ray to the next non-empty leaf along
// it (a DDA over the finest cells, front to back), sorts the rays by the variant of that leaf, and
// runs each variant's own kernel — its compiled shader, or the interpreter while that shader is
// not ready — on just its rays. A march that leaves its cell without a hit makes the ray active
// again for the next round. Shading and the constants are the CPU renderer's (csg_render.cpp).
#include "csg_trace_glsl.h"

#include "voxfield/csg_compile.h"

namespace voxfield::gpu::csg_trace {

std::string common() {
  return std::string(R"(#version 450
// voxfield: the Vulkan CSG renderer (src/render/gpu/csg_trace_glsl.cpp)
struct Leaf {
  vec4 lo, hi;      // the cell's box in model units
  int state;        // csg::CellState: 0 empty, 1 full, 2 surface
  int variant;      // surface cells
  uint param_base;  // the cell's first constant in vf_params
  int pad;
};
struct Ray {
  vec4 origin;  // w: where the next cell search starts (t)
  vec4 dir;     // w: where the ray leaves the traced box (t)
  int state;    // VF_ACTIVE, VF_QUEUED, VF_HIT, VF_MISS
  int leaf;     // queued: the cell to march; active: the cell just marched (not entered again)
  float t0, t1; // queued: the stretch of the ray inside that cell
};
struct Hit {
  vec4 normal_t;  // the surface normal, and t (negative: no hit)
  uint material;
  int leaf;
  uint pad0, pad1;
};
struct VariantInfo {
  uint program;    // its interpreter program in vf_program
  uint lipschitz;  // 0: steps of half the value (an ellipsoid beneath)
  uint pad0, pad1;
  vec4 colour;     // the variants view's colour (linear)
};
layout(std430, binding = 0) readonly buffer Frame {
  vec4 root_lo;  // w: the edge of the finest cells
  vec4 eye;      // w: 1 for an orthographic camera
  vec4 forward, right, up;
  vec4 sun;      // unit
  vec4 full_colour;  // the variants view's colour of full cells
  uint width, height, grid_n, variants;
  float scale, epsilon;
  uint whole_program, whole_params;  // the whole tape (0xFFFFFFFF: beyond the interpreter)
  uint view, shadows, max_groups_x, pad1;  // view 1: colour by variant
  vec4 albedo[256];                  // palette, linear
} fr;
layout(std430, binding = 1) readonly buffer Grid { int grid[]; };  // finest cells: leaf or -1
layout(std430, binding = 2) readonly buffer Leaves { Leaf leaves[]; };
layout(std430, binding = 3) readonly buffer Params { float vf_params[]; };
layout(std430, binding = 4) readonly buffer Programs { uint vf_program[]; };
layout(std430, binding = 5) readonly buffer Variants { VariantInfo vinfo[]; };
layout(std430, binding = 6) buffer Rays { Ray rays[]; };
layout(std430, binding = 7) buffer Hits { Hit hits[]; };
// Per round: the rays queued, then per variant its count, its queue offset and a cursor.
layout(std430, binding = 8) buffer Bins { uint queued; uint bins_pad[3]; uint bins[]; };
layout(std430, binding = 9) buffer Args { uint args[]; };  // indirect dispatch sizes per variant
layout(std430, binding = 10) buffer Queue { uint queue[]; };
layout(std430, binding = 11) writeonly buffer Pixels { uint pixels[]; };
layout(push_constant) uniform Push { uint mode; uint variant; } pc;  // mode 1: shadow rays

const int VF_ACTIVE = 0, VF_QUEUED = 1, VF_HIT = 2, VF_MISS = 3;
const int VF_EMPTY = 0, VF_FULL = 1, VF_SURFACE = 2;

float vf_param(uint i) { return vf_params[i]; }

uint vf_index() {
  return gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
}

// The camera's ray through pixel i (Camera::Projector::ray, pixel centres at +0.5).
void vf_camera_ray(uint i, out vec3 o, out vec3 d) {
  const uint px = i % fr.width, py = i / fr.width;
  const float sx = (2.0 * (float(px) + 0.5) - float(fr.width)) / float(fr.height) * fr.scale;
  const float sy = (float(fr.height) - 2.0 * (float(py) + 0.5)) / float(fr.height) * fr.scale;
  o = fr.eye.xyz;
  if (fr.eye.w != 0.0) {
    o += fr.right.xyz * sx + fr.up.xyz * sy;
    d = fr.forward.xyz;
  } else {
    d = normalize(fr.forward.xyz + fr.right.xyz * sx + fr.up.xyz * sy);
  }
}

// 1 / d with the zero components replaced by a tiny number of the same sign, so that the slab
// test needs no NaN cases (a ray parallel to a face never crosses it).
vec3 vf_inverse(vec3 d) {
  const vec3 s = mix(vec3(-1e-30), vec3(1e-30), greaterThanEqual(d, vec3(0.0)));
  return 1.0 / mix(d, s, lessThan(abs(d), vec3(1e-30)));
}

// The ray's parameter interval inside a box (empty when x > y).
vec2 vf_slab(vec3 o, vec3 inv, vec3 lo, vec3 hi) {
  const vec3 a = (lo - o) * inv, b = (hi - o) * inv;
  const vec3 near = min(a, b), far = max(a, b);
  return vec2(max(near.x, max(near.y, near.z)), min(far.x, min(far.y, far.z)));
}

vec3 vf_root_hi() { return fr.root_lo.xyz + vec3(fr.root_lo.w * float(fr.grid_n)); }
)") + csg::glsl_prelude() +
         csg::glsl_interpreter();
}

std::string init_main() {
  return R"(layout(local_size_x = 64) in;
void main() {
  const uint i = vf_index();
  if (i >= fr.width * fr.height) return;
  vec3 o, d;
  vf_camera_ray(i, o, d);
  if (pc.mode == 0u) {
    hits[i].normal_t = vec4(0.0, 0.0, 0.0, -1.0);
    hits[i].material = 0u;
    hits[i].leaf = -1;
  } else {
    // A shadow ray from each lit-facing hit, started off the surface along its normal.
    const Hit h = hits[i];
    if (h.normal_t.w < 0.0 || dot(h.normal_t.xyz, fr.sun.xyz) <= 0.0) {
      rays[i].state = VF_MISS;
      return;
    }
    o = o + d * h.normal_t.w + h.normal_t.xyz * (fr.epsilon * 4.0);
    d = fr.sun.xyz;
  }
  const vec2 t = vf_slab(o, vf_inverse(d), fr.root_lo.xyz, vf_root_hi());
  const float t0 = max(t.x, 0.0);
  rays[i].origin = vec4(o, t0);
  rays[i].dir = vec4(d, t.y);
  rays[i].state = t0 <= t.y ? VF_ACTIVE : VF_MISS;
  rays[i].leaf = -1;
}
)";
}

std::string advance_main() {
  return R"(layout(local_size_x = 64) in;
void main() {
  const uint i = vf_index();
  if (i >= fr.width * fr.height) return;
  Ray r = rays[i];
  if (r.state != VF_ACTIVE) return;
  const vec3 o = r.origin.xyz, d = r.dir.xyz, inv = vf_inverse(d);
  const float t = r.origin.w, t_end = r.dir.w, edge = fr.root_lo.w;
  const int n = int(fr.grid_n);
  // Amanatides and Woo's traversal of the finest cells from the one holding the ray at t.
  ivec3 c = clamp(ivec3(floor((o + d * t - fr.root_lo.xyz) / edge)), ivec3(0), ivec3(n - 1));
  const ivec3 step = ivec3(greaterThanEqual(d, vec3(0.0))) * 2 - 1;
  vec3 next = (fr.root_lo.xyz + vec3(c + max(step, ivec3(0))) * edge - o) * inv;
  const vec3 delta = abs(vec3(edge) * inv);
  for (int k = 0; k < 3 * n + 3; ++k) {
    const int leaf = grid[(c.z * n + c.y) * n + c.x];
    if (leaf >= 0 && leaf != r.leaf) {
      const Leaf cell = leaves[leaf];
      const vec2 lt = vf_slab(o, inv, cell.lo.xyz, cell.hi.xyz);
      const float t0 = max(lt.x, t), t1 = min(lt.y, t_end);
      // After a march the ray restarts at that cell's exit: a neighbour touched only there (an
      // edge or a corner, t0 == t1) is passed, or two such cells could hand the ray back and forth.
      if (t0 < t1 || (t0 == t1 && r.leaf < 0)) {
        if (cell.state == VF_FULL) {  // the surface is at its face
          rays[i].state = VF_HIT;
          if (pc.mode == 0u) {
            hits[i].normal_t = vec4(0.0, 0.0, 0.0, t0);
            hits[i].leaf = leaf;
          }
          return;
        }
        rays[i].state = VF_QUEUED;
        rays[i].leaf = leaf;
        rays[i].t0 = t0;
        rays[i].t1 = t1;
        atomicAdd(bins[cell.variant], 1u);
        atomicAdd(queued, 1u);
        return;
      }
    }
    const float tn = min(next.x, min(next.y, next.z));
    if (tn > t_end) break;
    if (next.x == tn) {
      c.x += step.x;
      next.x += delta.x;
    } else if (next.y == tn) {
      c.y += step.y;
      next.y += delta.y;
    } else {
      c.z += step.z;
      next.z += delta.z;
    }
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(n)))) break;
  }
  rays[i].state = VF_MISS;
}
)";
}

std::string bin_main() {
  return R"(layout(local_size_x = 1) in;
void main() {
  const uint v_count = fr.variants;
  uint sum = 0u;
  for (uint v = 0u; v < v_count; ++v) {
    const uint count = bins[v];
    bins[v_count + v] = sum;
    bins[2u * v_count + v] = sum;
    // Workgroups split over y past the device's limit along x (vf_index reads them back).
    const uint groups = (count + 63u) / 64u, x = min(groups, fr.max_groups_x);
    args[3u * v] = x;
    args[3u * v + 1u] = x == 0u ? 1u : (groups + x - 1u) / x;
    args[3u * v + 2u] = 1u;
    sum += count;
  }
}
)";
}

std::string scatter_main() {
  return R"(layout(local_size_x = 64) in;
void main() {
  const uint i = vf_index();
  if (i >= fr.width * fr.height || rays[i].state != VF_QUEUED) return;
  const uint v = uint(leaves[rays[i].leaf].variant);
  queue[atomicAdd(bins[2u * fr.variants + v], 1u)] = i;
}
)";
}

std::string march_main(const std::string& eval) {
  // vf_eval has one call site: a generated variant can be long, and each call site is inlined.
  // After a hit the same loop takes the six samples of the normal.
  return eval + R"(layout(local_size_x = 64) in;
void main() {
  const uint k = vf_index(), v = pc.variant;
  if (k >= bins[v]) return;
  const uint i = queue[bins[fr.variants + v] + k];
  const Ray r = rays[i];
  const uint base = leaves[r.leaf].param_base;
  const float factor = vinfo[v].lipschitz != 0u ? 1.0 : 0.5, eps = fr.epsilon, e = eps * 2.0;
  const vec3 o = r.origin.xyz, d = r.dir.xyz;
  float t = r.t0, samples[6];
  int steps = 0, probe = -1;  // probe >= 0: taking the normal's samples around the hit
  vec3 hit_p;
  uint m, hit_m = 0u;
  for (;;) {
    vec3 q;
    if (probe < 0) {
      if (steps >= 256 || t > r.t1) break;
      q = o + d * t;
    } else {
      vec3 offset = vec3(0.0);
      offset[probe >> 1] = (probe & 1) == 0 ? e : -e;
      q = hit_p + offset;
    }
    const float value = vf_eval(q, base, m);
    if (probe >= 0) {
      samples[probe] = value;
      if (++probe < 6) continue;
      vec3 nrm = vec3(samples[0] - samples[1], samples[2] - samples[3], samples[4] - samples[5]);
      nrm = length(nrm) > 0.0 ? normalize(nrm) : -d;
      if (dot(nrm, d) > 0.0) nrm = -nrm;
      hits[i].normal_t = vec4(nrm, t);
      hits[i].material = hit_m;
      hits[i].leaf = r.leaf;
      return;
    }
    ++steps;
    if (value < eps) {
      rays[i].state = VF_HIT;
      if (pc.mode != 0u) return;  // a shadow ray only needs to know
      // Normal and material from this cell's evaluator: the material at the hit, then six samples.
      hit_p = q;
      hit_m = m;
      probe = 0;
      continue;
    }
    t += max(value * factor, eps * 0.5);
  }
  rays[i].state = VF_ACTIVE;  // on to the next cell
  rays[i].origin.w = r.t1;
}
)";
}

std::string full_hits_main(const std::string& eval) {
  return eval + R"(layout(local_size_x = 64) in;
void main() {
  const uint i = vf_index();
  if (i >= fr.width * fr.height) return;
  const Hit h = hits[i];
  if (h.normal_t.w < 0.0 || leaves[h.leaf].state == VF_SURFACE) return;
  vec3 o, d;
  vf_camera_ray(i, o, d);
  const vec3 p = o + d * h.normal_t.w;
  const float e = fr.epsilon * 2.0;
  float samples[7];
  uint m;
  for (int k = 0; k < 7; ++k) {  // six around p, then p (one call site, as in the march)
    vec3 offset = vec3(0.0);
    if (k < 6) offset[k >> 1] = (k & 1) == 0 ? e : -e;
    samples[k] = vf_eval(p + offset, fr.whole_params, m);
  }
  vec3 nrm = vec3(samples[0] - samples[1], samples[2] - samples[3], samples[4] - samples[5]);
  nrm = length(nrm) > 0.0 ? normalize(nrm) : -d;
  if (dot(nrm, d) > 0.0) nrm = -nrm;
  hits[i].normal_t.xyz = nrm;
  hits[i].material = m;
}
)";
}

std::string shade_main() {
  return R"(layout(local_size_x = 64) in;
const vec3 kSunLight = vec3(2.4, 2.2, 1.9);
const vec3 kSkyZenith = vec3(0.22, 0.38, 0.78);
const vec3 kSkyHorizon = vec3(0.70, 0.80, 0.92);
const vec3 kGround = vec3(0.42, 0.45, 0.50);
const vec3 kSkyAmbient = vec3(0.42, 0.52, 0.70);

vec3 sky(vec3 dir) {
  if (dir.z < 0.0) return mix(kSkyHorizon, kGround, min(1.0, -dir.z * 3.0));
  return mix(kSkyHorizon, kSkyZenith, pow(dir.z, 0.6));
}

// Exposure and the sRGB curve, as RGBA bytes (src/render/shading.h).
uint tone(vec3 c) {
  const vec3 exposed = 1.0 - exp(-1.25 * max(c, vec3(0.0)));
  const vec3 s = mix(12.92 * exposed, 1.055 * pow(exposed, vec3(1.0 / 2.4)) - 0.055,
                     greaterThan(exposed, vec3(0.0031308)));
  const uvec3 b = uvec3(clamp(s, 0.0, 1.0) * 255.0 + 0.5);
  return b.x | (b.y << 8) | (b.z << 16) | (255u << 24);
}

void main() {
  const uint i = vf_index();
  if (i >= fr.width * fr.height) return;
  vec3 o, d;
  vf_camera_ray(i, o, d);
  const Hit h = hits[i];
  vec3 colour = sky(d);
  if (h.normal_t.w >= 0.0) {
    const vec3 nrm = h.normal_t.xyz;
    const uint material = h.material;
    const Leaf cell = leaves[h.leaf];
    vec3 base = fr.albedo[material & 255u].rgb;
    if (fr.view == 1u) base = cell.state == VF_SURFACE ? vinfo[cell.variant].colour.rgb : fr.full_colour.rgb;
    const float ndotl = max(0.0, dot(nrm, fr.sun.xyz));
    const float shadow = fr.shadows != 0u && ndotl > 0.0 && rays[i].state == VF_HIT ? 0.0 : 1.0;
    const vec3 ambient = mix(kGround, kSkyAmbient, 0.5 + 0.5 * nrm.z);
    colour = base * (kSunLight * (ndotl * shadow) + ambient);
  }
  pixels[i] = tone(colour);
}
)";
}

}  // namespace voxfield::gpu::csg_trace
