// voxfield_vectors.glsl — sampling voxfield's vector-field volume textures in shaders (GLSL 4.50,
// Vulkan or OpenGL). The same function as the C++ sample_vectors (voxfield/vectors.h): the world
// point into the oriented box, trilinear between voxel centres with clamp-to-edge, the channels
// decoded, and zero outside the box.
//
// Two ways to read the texels:
//  * vf_vectors_sample(sampler3D, volume, world): the texture as a 3-D image with linear filtering
//    and clamp-to-edge addressing, uploaded from VectorTexture::bytes() (x fastest) as
//    R8G8B8A8_UNORM (rgba8), R16G16B16A16_SFLOAT (rgba16f) or R32G32B32A32_SFLOAT (rgba32f);
//    the hardware filters (on most GPUs with 8 bits of sub-texel precision, so values differ from
//    the C++ sampler by up to about 1/256 of the texel differences).
//  * vf_vectors_sample_texels(volume, world): for texels kept in a storage buffer. Define
//    VF_VECTORS_TEXEL_FETCH before including this file and give
//        vec4 vf_vectors_texel(ivec3 voxel);
//    returning the channels as the image would (rgba8 as bytes / 255, floats as they are).
//
// Decoding (docs/vectors.md): rgba8 direction = 2 * channel - 1, strength = alpha; the float
// storages hold the direction and strength as they are. The direction is the interpolated one,
// not renormalised; the world-space vector is direction * strength.
#ifndef VOXFIELD_VECTORS_GLSL
#define VOXFIELD_VECTORS_GLSL

const uint VF_VECTORS_RGBA8 = 0u, VF_VECTORS_RGBA16F = 1u, VF_VECTORS_RGBA32F = 2u;

// VectorVolume: world = centre + rotation * local, local in [-size/2, size/2] (rotation's columns
// are the box's axes in world space: mat3(column 0, column 1, column 2)).
struct VfVectorVolume {
  vec3 centre;
  vec3 size;       // full extents along the box's axes, world units
  mat3 rotation;   // box axes -> world
  ivec3 resolution;
  uint storage;    // VF_VECTORS_RGBA8, _RGBA16F or _RGBA32F
};

struct VfVectorSample {
  vec3 direction;  // interpolated, not renormalised
  float strength;
  bool inside;     // false outside the box: direction and strength 0
};

// Volume coordinates of a world point: [0, 1]^3 inside the box.
vec3 vf_vectors_to_volume(VfVectorVolume v, vec3 world) {
  return transpose(v.rotation) * (world - v.centre) / v.size + 0.5;
}

bool vf_vectors_inside(vec3 u) {
  return all(greaterThanEqual(u, vec3(0.0))) && all(lessThanEqual(u, vec3(1.0)));
}

// Raw channels (as a texture returns them) to direction (xyz) and strength (w).
vec4 vf_vectors_decode(vec4 raw, uint storage) {
  return storage == VF_VECTORS_RGBA8 ? vec4(raw.xyz * 2.0 - 1.0, raw.w) : raw;
}

VfVectorSample vf_vectors_result(vec4 decoded, bool inside) {
  VfVectorSample s;
  s.direction = inside ? decoded.xyz : vec3(0.0);
  s.strength = inside ? decoded.w : 0.0;
  s.inside = inside;
  return s;
}

VfVectorSample vf_vectors_sample(sampler3D field, VfVectorVolume v, vec3 world) {
  const vec3 u = vf_vectors_to_volume(v, world);
  if (!vf_vectors_inside(u)) return vf_vectors_result(vec4(0.0), false);
  return vf_vectors_result(vf_vectors_decode(textureLod(field, u, 0.0), v.storage), true);
}

#ifdef VF_VECTORS_TEXEL_FETCH
vec4 vf_vectors_texel(ivec3 voxel);

VfVectorSample vf_vectors_sample_texels(VfVectorVolume v, vec3 world) {
  const vec3 u = vf_vectors_to_volume(v, world);
  if (!vf_vectors_inside(u)) return vf_vectors_result(vec4(0.0), false);
  // Voxel-centre coordinates clamped to the outer centres: what linear filtering with
  // clamp-to-edge computes.
  const vec3 t = clamp(u * vec3(v.resolution) - 0.5, vec3(0.0), vec3(v.resolution - 1));
  const ivec3 i0 = ivec3(floor(t)), i1 = min(i0 + 1, v.resolution - 1);
  const vec3 f = t - vec3(i0);
  vec4 acc = vec4(0.0);
  for (int c = 0; c < 8; ++c) {
    const ivec3 corner = ivec3(c & 1, (c >> 1) & 1, c >> 2);
    const vec3 w = mix(1.0 - f, f, vec3(corner));
    acc += w.x * w.y * w.z * vf_vectors_decode(vf_vectors_texel(mix(i0, i1, bvec3(corner))), v.storage);
  }
  return vf_vectors_result(acc, true);
}
#endif

#endif  // VOXFIELD_VECTORS_GLSL
