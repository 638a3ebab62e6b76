// voxfield — the vector-field visualiser on the GPU (src/vectors/visualise.cpp; Hamlin,
// "Volumetric Interaction", section 3.4): each pixel's ray is intersected with the volume's box by
// the slab method in volume coordinates, then marched front to back, compositing an
// emission-absorption medium whose density follows the strength and whose colour follows the
// direction, and the reactive sheet (a height field displaced by the field's vector, found by the
// sign change of the ray's height above it, then bisection). It samples the texture through
// voxfield_vectors.glsl, the include applications use, in floats (the CPU renders in doubles:
// images agree within the tolerance tests/test_gpu_vector_passes states).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"
#include "split_buffer.glsl"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 7) readonly buffer Texels { uint texels[]; };
layout(std430, set = 0, binding = 10) readonly buffer View { VectorViewParams view; };
// The image (RGBA8) in four windows of 2^view.image.w words: a large image outgrows one binding.
VF_SPLIT_WORDS(writeonly, Pixels, pixels, 11, 12, 13, 14);
VF_SPLIT_STORE(pixels, uint(view.image.w))

#define VF_VECTORS_TEXEL_FETCH
#include "voxfield/glsl/voxfield_vectors.glsl"

vec4 vf_vectors_texel(ivec3 i) {
  const ivec3 n = view.resolution.xyz;
  const uint storage = uint(view.resolution.w);
  const uint words = storage == 0u ? 1u : storage == 1u ? 2u : 4u;
  const uint at = words * uint(i.x + n.x * (i.y + n.y * i.z));
  if (storage == 0u) return unpackUnorm4x8(texels[at]);
  if (storage == 1u) return vec4(unpackHalf2x16(texels[at]), unpackHalf2x16(texels[at + 1u]));
  return uintBitsToFloat(uvec4(texels[at], texels[at + 1u], texels[at + 2u], texels[at + 3u]));
}

uint to_srgb8(float linear) {
  const float c = clamp(linear, 0.0, 1.0);
  const float s = c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
  return uint(floor(s * 255.0 + 0.5));
}

// The sheet's height at volume coordinates (x, y): its rest height pushed along the box's z axis
// by the field's vector there, clamped to the box.
float sheet_height(VfVectorVolume v, float x, float y, out VfVectorSample s) {
  const vec3 rest = v.centre + v.rotation * ((vec3(x, y, view.sheet.y) - 0.5) * v.size);
  s = vf_vectors_sample_texels(v, rest);
  return clamp(view.sheet.y + view.sheet.z * dot(s.direction * s.strength, v.rotation[2]), 0.0, 1.0);
}

float sheet_height(VfVectorVolume v, float x, float y) {
  VfVectorSample s;
  return sheet_height(v, x, y, s);
}

// Lit colour at (x, y), as visualise.cpp's Sheet::colour.
vec3 sheet_colour(VfVectorVolume v, float x, float y) {
  const float ex = 1.0 / float(v.resolution.x), ey = 1.0 / float(v.resolution.y);
  const float dx = (sheet_height(v, x + ex, y) - sheet_height(v, x - ex, y)) / (2.0 * ex) * v.size.z / v.size.x;
  const float dy = (sheet_height(v, x, y + ey) - sheet_height(v, x, y - ey)) / (2.0 * ey) * v.size.z / v.size.y;
  const vec3 normal = normalize(vec3(-dx, -dy, 1.0));
  const float diffuse = abs(dot(normal, normalize(vec3(0.4, 0.3, 1.0))));
  VfVectorSample s;
  sheet_height(v, x, y, s);
  const float len = length(s.direction);
  const vec3 tint = len > 0.0 ? s.direction / len : vec3(0.0);
  const vec3 base = vec3(0.18, 0.42, 0.16);
  return mix(base, 0.15 + 0.85 * abs(tint), clamp(s.strength, 0.0, 1.0)) * (0.25 + 0.75 * diffuse);
}

void pixel(uint i) {
  const int width = view.image.x, height = view.image.y;
  const int x = int(i % uint(width)), y = int(i / uint(width));
  VfVectorVolume v;
  v.centre = view.centre.xyz;
  v.size = view.size.xyz;
  v.rotation = mat3(view.axis_x.xyz, view.axis_y.xyz, view.axis_z.xyz);
  v.resolution = view.resolution.xyz;
  v.storage = uint(view.resolution.w);
  const vec3 eye = view.eye.xyz;
  const vec3 dir = normalize(view.dir00.xyz + view.dx.xyz * float(x) + view.dy.xyz * float(y));
  const vec3 o = vf_vectors_to_volume(v, eye), d = vf_vectors_to_volume(v, eye + dir) - o;
  float t0 = 0.0, t1 = 3.0e38;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0) {
      if (o[a] < 0.0 || o[a] > 1.0) t1 = -1.0;
      continue;
    }
    float ta = (0.0 - o[a]) / d[a], tb = (1.0 - o[a]) / d[a];
    if (ta > tb) {
      const float swap = ta;
      ta = tb;
      tb = swap;
    }
    t0 = max(t0, ta);
    t1 = min(t1, tb);
  }
  vec3 colour = vec3(0.02, 0.025, 0.035);  // background
  if (t0 < t1) {
    const float step = view.march.x, density = view.march.y;
    const int steps = int(ceil(min(t1 - t0, view.march.z * step) / step));
    float transmittance = 1.0;
    vec3 acc = vec3(0.0);
    const bool sheet = view.sheet.x > 0.5;
    float last_t = t0, last_side = 0.0;
    if (sheet) {
      const vec3 u = o + d * t0;
      last_side = u.z - sheet_height(v, u.x, u.y);
    }
    for (int k = 0; k < steps && transmittance > 0.004; ++k) {
      const float t = t0 + (float(k) + 0.5) * step;
      if (sheet) {
        vec3 u = o + d * t;
        const float side = u.z - sheet_height(v, u.x, u.y);
        if ((side > 0.0) != (last_side > 0.0)) {
          float lo = last_t, hi = t;  // the crossing lies between: bisect
          for (int i = 0; i < 8; ++i) {
            const float mid = 0.5 * (lo + hi);
            const vec3 m = o + d * mid;
            if ((m.z - sheet_height(v, m.x, m.y) > 0.0) == (last_side > 0.0)) lo = mid; else hi = mid;
          }
          u = o + d * (0.5 * (lo + hi));
          acc += transmittance * sheet_colour(v, u.x, u.y);
          transmittance = 0.0;
          break;
        }
        last_t = t;
        last_side = side;
      }
      const VfVectorSample s = vf_vectors_sample_texels(v, eye + dir * t);
      if (s.strength <= 0.0) continue;
      const float alpha = 1.0 - exp(-density * s.strength * step);
      const float len = length(s.direction);
      const vec3 c = len > 0.0 ? s.direction / len : vec3(0.5);
      acc += transmittance * alpha * (0.15 + 0.85 * abs(c));
      transmittance *= 1.0 - alpha;
    }
    colour = acc + transmittance * colour;
  }
  const uvec3 c = uvec3(to_srgb8(colour.r), to_srgb8(colour.g), to_srgb8(colour.b));
  pixels_store(i, (view.image.z != 0 ? (c.b | (c.r << 16)) : (c.r | (c.b << 16))) | (c.g << 8) |
                     (255u << 24));
}

void main() {
  const uint pixel_count = uint(view.image.x * view.image.y);
  for (uint i = gl_GlobalInvocationID.x; i < pixel_count; i += gl_NumWorkGroups.x * gl_WorkGroupSize.x)
    pixel(i);
}
