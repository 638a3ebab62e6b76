// voxfield — the ray marcher on the GPU: the CPU renderer (src/render/) in GLSL, one invocation
// per pixel. Same traversal (Amanatides & Woo DDA with exact bulk skips out of empty chunks and out
// of boxes the skip field clears — see src/render/dda.h for why a skip lands exactly where the
// plain DDA would), same bricked data, same shading (palette albedo, sun with soft shadows, sky
// with ambient occlusion from the Euclidean field, fog, sky gradient, exposure and sRGB). Floats
// instead of doubles: a ray grazing a voxel edge may pick the neighbouring voxel, so images match
// the CPU's within a tolerance rather than bit for bit (tests/test_gpu.cpp).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "split_buffer.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer ParamsBuf { RenderParams rp; };
layout(std430, set = 0, binding = 1) readonly buffer ChunkInfo { uint chunk_info[]; };
layout(std430, set = 0, binding = 4) readonly buffer Palette { vec4 albedo[]; };  // linear RGB
// The error view's approximate field: per chunk its slot (or VF_UNIFORM) and its uniform cell |
// smallest distance << 16; cells as in the skip arena.
layout(std430, set = 0, binding = 6) readonly buffer ApproxInfo { uint approx_info[]; };
// The arenas and the image, each bound as four windows of 2^rp.part_shift words (a large scene's
// arenas and a large image outgrow one binding): the skip arena (u16 per voxel: distance, material
// above it), the lighting arena (u8 per voxel), the image (RGBA8), the approximation's arena.
VF_SPLIT_WORDS(readonly, SkipArena, skip_words, 2, 8, 9, 10);
VF_SPLIT_WORDS(readonly, LightArena, light_words, 3, 11, 12, 13);
VF_SPLIT_WORDS(writeonly, Image, pixel_words, 5, 14, 15, 16);
VF_SPLIT_WORDS(readonly, ApproxArena, approx_words, 7, 17, 18, 19);
VF_SPLIT_LOAD(skip_words, rp.part_shift)
VF_SPLIT_LOAD(light_words, rp.part_shift)
VF_SPLIT_STORE(pixel_words, rp.part_shift)
VF_SPLIT_LOAD(approx_words, rp.part_shift)

const float kInf = 1.0 / 0.0;

// ---- the chunk table and the bricked voxels (src/render/volume.h) ------------------------------

uint chunk_index(ivec3 v) {
  const int s = rp.first_chunk.w;
  const ivec3 c = (v >> s) - rp.first_chunk.xyz;
  return uint((c.z * rp.chunk_dims.y + c.y) * rp.chunk_dims.x + c.x);
}

uint brick_index(ivec3 v) {
  const int s = rp.first_chunk.w, m = (1 << s) - 1, bs = s - 2;
  const uvec3 b = uvec3((v & m) >> 2);
  const uint brick = (((b.z << bs) | b.y) << bs) | b.x;
  return (brick << 6) | (uint(v.z & 3) << 4) | (uint(v.y & 3) << 2) | uint(v.x & 3);
}

// Distance (low byte) and material (high byte) of a voxel.
uint skip_cell(uint chunk, ivec3 v) {
  const uint slot = chunk_info[4 * chunk];
  if (slot == VF_UNIFORM) return chunk_info[4 * chunk + 1] & 0xFFFFu;
  const uint i = slot * uint(rp.chunk_dims.w) + brick_index(v);
  return (skip_words(i >> 1) >> ((i & 1u) * 16u)) & 0xFFFFu;
}

uint chunk_min(uint chunk) { return (chunk_info[4 * chunk + 1] >> 16) & 0xFFu; }

// The same reads from the exact skip field or the error view's approximation.
uint cell_of(bool approx, uint chunk, ivec3 v) {
  if (!approx) return skip_cell(chunk, v);
  const uint slot = approx_info[2 * chunk];
  if (slot == VF_UNIFORM) return approx_info[2 * chunk + 1] & 0xFFFFu;
  const uint i = slot * uint(rp.chunk_dims.w) + brick_index(v);
  return (approx_words(i >> 1) >> ((i & 1u) * 16u)) & 0xFFFFu;
}
uint min_of(bool approx, uint chunk) { return approx ? (approx_info[2 * chunk + 1] >> 16) & 0xFFu : chunk_min(chunk); }
bool chunk_empty(uint chunk) { return (chunk_info[4 * chunk + 1] & (1u << 24)) != 0u; }
bool chunk_dense(uint chunk) { return (chunk_info[4 * chunk + 1] & (1u << 25)) != 0u; }

float light_value(ivec3 v) {
  const uint chunk = chunk_index(v);
  const uint slot = chunk_info[4 * chunk + 2];
  uint stored;
  if (slot == VF_UNIFORM) {
    stored = chunk_info[4 * chunk + 3];
  } else {
    const uint i = slot * uint(rp.chunk_dims.w) + brick_index(v);
    stored = (light_words(i >> 2) >> ((i & 3u) * 8u)) & 0xFFu;
  }
  return float(stored) * rp.light_inv_scale;
}

// ---- the DDA with exact bulk skips (src/render/dda.h) ------------------------------------------

ivec3 d_v, d_step, d_boundary;
vec3 d_origin, d_inv, d_abs, d_tnext;
float d_t;
int d_face;

float t_at(int a, int j) { return (float(d_boundary[a] + j * d_step[a]) - d_origin[a]) * d_inv[a]; }

void d_start(vec3 o, vec3 dir, ivec3 v, float t0, int face) {
  d_v = v;
  d_t = t0;
  d_face = face;
  d_origin = o;
  for (int a = 0; a < 3; ++a) {
    d_step[a] = dir[a] > 0.0 ? 1 : dir[a] < 0.0 ? -1 : 0;
    d_inv[a] = d_step[a] != 0 ? 1.0 / dir[a] : 0.0;
    d_abs[a] = abs(dir[a]);
    d_boundary[a] = v[a] + (d_step[a] > 0 ? 1 : 0);
    d_tnext[a] = d_step[a] != 0 ? t_at(a, 0) : kInf;
  }
}

void advance(int a, int n) {
  d_v[a] += n * d_step[a];
  d_boundary[a] += n * d_step[a];
  d_tnext[a] = t_at(a, 0);
}

void step_once() {
  const int a = (d_tnext.x <= d_tnext.y && d_tnext.x <= d_tnext.z) ? 0 : (d_tnext.y <= d_tnext.z ? 1 : 2);
  d_t = d_tnext[a];
  d_face = a;
  advance(a, 1);
}

// The first event leaving the box that reaches caps[a] voxels ahead: (t, axis).
void exit_of(ivec3 caps, out float et, out int ea) {
  et = kInf;
  ea = 3;
  for (int a = 0; a < 3; ++a) {
    if (d_step[a] == 0) continue;
    const float ta = t_at(a, caps[a]);
    if (ta < et || (ta == et && a < ea)) { et = ta; ea = a; }
  }
}

bool before(int b, float tb, float et, int ea) { return tb < et || (tb == et && b < ea); }

// Dda::leave (src/render/dda.h): the crossings before the exit counted from a ceil estimate that
// exact comparisons settle, the last crossing time compared kept as the axis' next event.
void leave(ivec3 caps, float et, int ea) {
  for (int b = 0; b < 3; ++b) {
    if (d_step[b] == 0) continue;
    if (b == ea) { advance(b, caps[b] + 1); continue; }
    int j = int(clamp(ceil((et - d_tnext[b]) * d_abs[b]), 0.0, float(caps[b])));
    float tj = t_at(b, j);
    if (before(b, tj, et, ea)) {
      do { ++j; tj = t_at(b, j); } while (j < caps[b] && before(b, tj, et, ea));
    } else {
      while (j > 0) {
        const float earlier = t_at(b, j - 1);
        if (before(b, earlier, et, ea)) break;
        --j;
        tj = earlier;
      }
    }
    d_v[b] += j * d_step[b];
    d_boundary[b] += j * d_step[b];
    d_tnext[b] = tj;
  }
  d_t = et;
  d_face = ea;
}

// Caps of a box around an air voxel that the skip field clears (src/render/traverse.h).
ivec3 skip_caps(vec3 w, uint stored) {
  if (rp.metric == VF_EUCLIDEAN) {
    const float r = float(stored) * rp.skip_inv_scale * (1.0 - 1e-6);
    return ivec3(r * w);
  }
  const int r = stored > 0u ? int(stored) - 1 : 0;
  if (rp.metric == VF_CHEBYSHEV) return ivec3(r);
  vec3 share = float(r) * w;
  ivec3 caps = ivec3(share);
  vec3 rest = vec3(w.x > 0.0 ? share.x - float(caps.x) : -1.0, w.y > 0.0 ? share.y - float(caps.y) : -1.0,
                   w.z > 0.0 ? share.z - float(caps.z) : -1.0);
  for (int left = r - (caps.x + caps.y + caps.z); left > 0; --left) {
    const int a = rest.x >= rest.y && rest.x >= rest.z ? 0 : (rest.y >= rest.z ? 1 : 2);
    caps[a] += 1;
    rest[a] = -1.0;
  }
  return caps;
}

vec3 skip_weights(vec3 dir) {
  const vec3 a = abs(dir);
  if (rp.metric == VF_CHEBYSHEV) return vec3(1.0);
  const float norm = rp.metric == VF_MANHATTAN ? a.x + a.y + a.z : length(a);
  return a / norm;
}

// The box rays walk: the render box, or in the distance view the part below the cut.
ivec3 g_lo, g_hi;

bool start_in_box(vec3 o, vec3 dir) {
  float t0 = -kInf, t1 = kInf;
  int axis0 = -1;
  for (int a = 0; a < 3; ++a) {
    const float lo = float(g_lo[a]), hi = float(g_hi[a]);
    if (dir[a] == 0.0) {
      if (o[a] < lo || o[a] >= hi) return false;
      continue;
    }
    float ta = (lo - o[a]) / dir[a], tb = (hi - o[a]) / dir[a];
    if (ta > tb) { const float x = ta; ta = tb; tb = x; }
    if (ta > t0) { t0 = ta; axis0 = a; }
    t1 = min(t1, tb);
  }
  const float ts = max(t0, 0.0);
  if (!(t1 > ts)) return false;
  ivec3 v;
  for (int a = 0; a < 3; ++a) v[a] = clamp(int(floor(o[a] + dir[a] * ts)), g_lo[a], g_hi[a] - 1);
  const int face = t0 > 0.0 ? axis0 : -1;
  if (face >= 0) v[face] = dir[face] > 0.0 ? g_lo[face] : g_hi[face] - 1;
  d_start(o, dir, v, ts, face);
  return true;
}

bool in_box(ivec3 v) { return all(greaterThanEqual(v, g_lo)) && all(lessThan(v, g_hi)); }

// Traces from the current DDA state to the first solid voxel. shadow: track the soft-shadow
// penumbra at the air voxels visited (min k * (e - 0.75) / t beyond t = 1.5).
uint g_material;
float g_penumbra;
bool trace(vec3 dir, bool shadow, bool approx) {
  const vec3 w = skip_weights(dir);
  for (int guard = 0; guard < 100000; ++guard) {
    if (!in_box(d_v)) return false;
    const uint chunk = chunk_index(d_v);
    if (shadow && d_t >= 1.5) g_penumbra = min(g_penumbra, 5.0 * (light_value(d_v) - 0.75) / d_t);
    if (chunk_empty(chunk)) {
      const int s = rp.first_chunk.w;
      const ivec3 lo = (d_v >> s) << s, hi = lo + ivec3(1 << s);
      ivec3 caps;
      for (int a = 0; a < 3; ++a) caps[a] = d_step[a] > 0 ? hi[a] - 1 - d_v[a] : d_v[a] - lo[a];
      const ivec3 dcaps = skip_caps(w, min_of(approx, chunk));
      float et; int ea;
      if (shadow) {
        // Shadow rays sample the air where they stop: the farther of the chunk's box and the
        // distance's box (leave_empty_chunk in src/render/traverse.h).
        exit_of(caps, et, ea);
        float dt; int da;
        exit_of(dcaps, dt, da);
        if (dt > et || (dt == et && da > ea)) leave(dcaps, dt, da); else leave(caps, et, ea);
        continue;
      }
      // The chunk's box extended beyond its far faces by the caps of its smallest distance
      // (leave_empty_chunk says why it holds no solid voxel).
      caps += dcaps;
      exit_of(caps, et, ea);
      leave(caps, et, ea);
      continue;
    }
    const uint cell = cell_of(approx, chunk, d_v);
    const uint material = cell >> 8;
    if (material != 0u) { g_material = material; return true; }
    const ivec3 caps = skip_caps(w, cell & 0xFFu);
    if (caps.x + caps.y + caps.z > 0) {
      float et; int ea;
      exit_of(caps, et, ea);
      leave(caps, et, ea);
    } else {
      step_once();
    }
  }
  return false;
}

// ---- shading (src/render/renderer.cpp) -------------------------------------------------------

const vec3 kSunLight = vec3(2.4, 2.2, 1.9);
const vec3 kSkyZenith = vec3(0.22, 0.38, 0.78);
const vec3 kSkyHorizon = vec3(0.70, 0.80, 0.92);
const vec3 kGround = vec3(0.42, 0.45, 0.50);
const vec3 kSkyAmbient = vec3(0.42, 0.52, 0.70);

vec3 sky(vec3 dir) {
  if (dir.z < 0.0) return mix(kSkyHorizon, kGround, min(1.0, -dir.z * 3.0));
  return mix(kSkyHorizon, kSkyZenith, pow(dir.z, 0.6));
}

// The sky along a ray: for a camera placed in non-cubic voxels, the camera's sky_scale (in the
// basis' w) turns the ray into the world ray's direction along the voxel axes (shading.h).
vec3 sky_along(vec3 dir) {
  const vec3 s = vec3(rp.forward.w, rp.right.w, rp.up.w);
  return sky(s == vec3(1.0) ? dir : normalize(dir * s));
}

float light_at(vec3 q) {
  const vec3 f = q - 0.5;
  const ivec3 b = ivec3(floor(f));
  const vec3 t = f - vec3(b);
  float sum = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const ivec3 d = ivec3(corner & 1, (corner >> 1) & 1, corner >> 2);
    const ivec3 v = clamp(b + d, rp.box_begin.xyz, rp.box_end.xyz - 1);
    const vec3 wv = mix(1.0 - t, t, vec3(d));
    sum += wv.x * wv.y * wv.z * light_value(v);
  }
  return sum;
}

float ambient_occlusion(vec3 p, vec3 n) {
  const float steps[3] = float[3](0.5, 1.5, 3.0), weights[3] = float[3](0.5, 0.3, 0.2);
  float occlusion = 0.0;
  for (int i = 0; i < 3; ++i) {
    const float open = steps[i] + 0.5;
    occlusion += weights[i] * clamp((open - light_at(p + n * steps[i])) / open, 0.0, 1.0);
  }
  return clamp(1.0 - 1.7 * occlusion, 0.0, 1.0);
}

float soft_shadow(vec3 p, vec3 n) {
  const vec3 o = p + n * 1e-3;
  if (!start_in_box(o, rp.sun.xyz)) return 1.0;
  g_penumbra = 1.0;
  if (trace(rp.sun.xyz, true, false)) return 0.0;
  const float lit = clamp(g_penumbra, 0.0, 1.0);
  return lit * lit * (3.0 - 2.0 * lit);
}

// sRGB bytes as one packed pixel, in the order the frame asks for.
uint pack_bytes(uvec3 b) {
  return (rp.flags & VF_RENDER_BGRA) != 0u ? b.z | (b.y << 8) | (b.x << 16) | (255u << 24)
                                           : b.x | (b.y << 8) | (b.z << 16) | (255u << 24);
}

// Exposure and the sRGB curve, as bytes.
uvec3 tone_bytes(vec3 c) {
  const vec3 exposed = 1.0 - exp(-1.25 * max(c, vec3(0.0)));
  const vec3 s = mix(12.92 * exposed, 1.055 * pow(exposed, vec3(1.0 / 2.4)) - 0.055, greaterThan(exposed, vec3(0.0031308)));
  return uvec3(clamp(s, 0.0, 1.0) * 255.0 + 0.5);
}

uint encode(vec3 c) { return pack_bytes(tone_bytes(c)); }

// The heat ramp of the distance view (dark blue, blue, green, yellow, red) for x in [0, 1], as
// sRGB bytes (src/render/renderer.cpp: heat()).
uvec3 heat(float x) {
  const vec3 stops[5] = vec3[5](vec3(20, 12, 70), vec3(30, 100, 220), vec3(40, 190, 130), vec3(245, 215, 50),
                                vec3(215, 40, 30));
  x = clamp(x, 0.0, 1.0) * 4.0;
  const int i = min(3, int(x));
  const float f = x - float(i);
  return uvec3(floor(stops[i] * (1.0 - f) + stops[i + 1] * f + 0.5));
}

void main() {
  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  if (i >= rp.width * rp.height) return;
  const uint px = i % rp.width, py = i / rp.width;
  const float sx = (2.0 * (float(px) + 0.5) - float(rp.width)) / float(rp.height) * rp.scale;
  const float sy = (float(rp.height) - 2.0 * (float(py) + 0.5)) / float(rp.height) * rp.scale;
  vec3 origin = rp.eye.xyz, dir;
  if (rp.eye.w != 0.0) {
    origin += rp.right.xyz * sx + rp.up.xyz * sy;
    dir = rp.forward.xyz;
  } else {
    dir = normalize(rp.forward.xyz + rp.right.xyz * sx + rp.up.xyz * sy);
  }
  g_lo = rp.box_begin.xyz;
  g_hi = rp.box_end.xyz;
  if ((rp.flags & VF_RENDER_DISTANCE) != 0u) {
    g_hi.z = rp.slice_z + 1;
    // A ray entering the cut through its top face on an air voxel shows the field there, with a
    // darker band every 8 voxels of distance.
    if (start_in_box(origin, dir) && d_face == 2 && d_step.z < 0) {
      const uint cell = skip_cell(chunk_index(d_v), d_v);
      if ((cell >> 8) == 0u) {
        const float distance = float(cell & 0xFFu) * rp.skip_inv_scale;
        uvec3 b = heat(distance / max(1.0, float(rp.heat_top) * rp.skip_inv_scale));
        if (int(distance) % 8 == 0) b = b * 3u / 4u;
        pixel_words_store(i, pack_bytes(b));
        return;
      }
    }
  }
  // The error view: the plain DDA visits every voxel up to the true hit, recording the largest
  // |approximate - exact| on the way; then the approximation's own skipping walk must stop at
  // the same voxel, or the pixel is magenta (a ray let through geometry).
  float worst = 0.0;
  bool through = false;
  if ((rp.flags & VF_RENDER_ERROR) != 0u) {
    bool exact_hit = false;
    ivec3 exact_voxel = ivec3(0);
    if (start_in_box(origin, dir)) {
      for (int guard = 0; guard < 100000; ++guard) {
        if (!in_box(d_v)) break;
        const uint chunk = chunk_index(d_v);
        const uint cell = skip_cell(chunk, d_v);
        if ((cell >> 8) != 0u) { exact_hit = true; exact_voxel = d_v; break; }
        const float e = float(cell & 0xFFu) * rp.skip_inv_scale;
        const float a = float(cell_of(true, chunk, d_v) & 0xFFu) * rp.approx_inv_scale;
        worst = max(worst, abs(a - e));
        step_once();
      }
    }
    const bool skipped_hit = start_in_box(origin, dir) && trace(dir, false, true);
    through = skipped_hit != exact_hit || (exact_hit && d_v != exact_voxel);
  }
  vec3 color;
  if (!start_in_box(origin, dir) || !trace(dir, false, false)) {
    color = sky_along(dir);
  } else {
    const ivec3 voxel = d_v;
    const float t = d_t;
    const int face = d_face;
    const uint material = g_material;
    int axis = d_face, sign_ = axis >= 0 ? -d_step[axis] : 0;
    if (axis < 0) {
      const vec3 a = abs(dir);
      axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
      sign_ = dir[axis] > 0.0 ? -1 : 1;
    }
    vec3 n = vec3(0.0);
    n[axis] = float(sign_);
    const vec3 p = origin + dir * t;
    const float ndotl = max(0.0, dot(n, rp.sun.xyz));
    float shadow = 1.0;
    if ((rp.flags & VF_RENDER_SHADOWS) != 0u && ndotl > 0.0) shadow = soft_shadow(p, n);
    const float ao = (rp.flags & VF_RENDER_AO) != 0u ? ambient_occlusion(p, n) : 1.0;
    const vec3 ambient = mix(kGround, kSkyAmbient, 0.5 + 0.5 * n.z) * (0.35 + 0.65 * ao);
    color = albedo[material].xyz * (kSunLight * (ndotl * shadow) + ambient);
    if (rp.sun.w > 0.0) color = mix(color, sky_along(dir), 1.0 - exp(-rp.sun.w * t));
    if ((rp.flags & VF_RENDER_CHUNKS) != 0u) {
      // Chunk view: grid lines about a pixel wide, chunks tinted by storage.
      const float edge = float(1 << rp.first_chunk.w);
      const float foot =
          (rp.eye.w != 0.0 ? 1.0 : t) * 2.0 * rp.scale / float(rp.height) * rp.footprint_scale;
      const float width = max(0.04, 0.75 * foot);
      bool line = false;
      for (int a = 0; a < 3; ++a) {
        if (a == face) continue;
        const float m = p[a] - edge * floor(p[a] / edge);
        line = line || min(m, edge - m) < width;
      }
      color = mix(color, chunk_dense(chunk_index(voxel)) ? vec3(0.15, 0.35, 1.0) : vec3(1.0, 0.55, 0.1), 0.15);
      if (line) color = mix(color, vec3(0.02), 0.85);
    }
  }
  if ((rp.flags & VF_RENDER_ERROR) != 0u) {
    // Grey shading under the error: magenta where the approximation passes the true hit, else a
    // heat tint, logarithmic so that one step and dozens of voxels both stay readable.
    const float grey = 0.8 * dot(color, vec3(0.2126, 0.7152, 0.0722));
    uvec3 b = tone_bytes(vec3(grey));
    if (through) {
      b = uvec3(255u, 0u, 255u);
    } else if (worst > 0.0) {
      b = (2u * b + 3u * heat(log2(1.0 + worst) / 6.0)) / 5u;
    }
    pixel_words_store(i, pack_bytes(b));
    return;
  }
  pixel_words_store(i, encode(color));
}
