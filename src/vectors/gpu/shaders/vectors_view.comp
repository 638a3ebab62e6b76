// voxfield — the vector-field visualiser on the GPU (src/vectors/visualise.cpp; Hamlin,
// "Volumetric Interaction", section 3.4): each pixel's ray is intersected with the volume's box by
// the slab method in volume coordinates, then marched front to back, compositing an
// emission-absorption medium whose density follows the strength and whose colour follows the
// direction. It samples the texture through voxfield_vectors.glsl, the include applications use,
// in floats (the CPU renders in doubles: images agree within the tolerance tests/test_gpu_vectors
// states).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "layout.h"

layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 7) readonly buffer Texels { uint texels[]; };
layout(std430, set = 0, binding = 10) readonly buffer View { VectorViewParams view; };
layout(std430, set = 0, binding = 11) writeonly buffer Pixels { uint pixels[]; };

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

void main() {
  const uint i = gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x + gl_GlobalInvocationID.x;
  const int width = view.image.x, height = view.image.y;
  if (i >= uint(width * height)) return;
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
    for (int k = 0; k < steps && transmittance > 0.004; ++k) {
      const float t = t0 + (float(k) + 0.5) * step;
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
  pixels[i] = to_srgb8(colour.r) | (to_srgb8(colour.g) << 8) | (to_srgb8(colour.b) << 16) | (255u << 24);
}
