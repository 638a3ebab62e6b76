// voxfield renderer — the light at a primary ray's hit (internal): palette albedo under a sun with
// soft shadows and a sky dome with ambient occlusion, both read from the scene's clamped Euclidean
// lighting field (the "distance field soft shadows" of Quilez's SDF rendering notes, made exact in
// occlusion by tracing the shadow ray with the same DDA), and optional fog. Shared by the frame
// renderer (renderer.cpp), which walks a shadow ray through its whole scene, and the relay
// (relay.cpp), which walks it part by part across scenes and hands the shadow back here.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "dda.h"
#include "scene_impl.h"
#include "shading.h"

namespace voxfield::render_detail {

struct HitShading {
  const RenderScene::Impl& s;
  const RenderOptions& o;
  Vec3d sun;                 // normalised
  Vec3d sky_scale{1, 1, 1};  // the camera's (Camera::Projector::sky_scale), for the fog's sky

  static constexpr double kSoftness = 5, kNear = 1.5;

  std::uint8_t light_at_voxel(Vec3i v) const {
    return s.light.read(s.table.chunk_index(v), s.table.brick_index(v));
  }

  // The lighting field at a point, interpolated between voxel centres (clamped to the box).
  double light_at(const Vec3d& q) const {
    const Box3i& box = s.box;
    const double fx = q.x - 0.5, fy = q.y - 0.5, fz = q.z - 0.5;
    const int x0 = static_cast<int>(std::floor(fx)), y0 = static_cast<int>(std::floor(fy)),
              z0 = static_cast<int>(std::floor(fz));
    const double tx = fx - x0, ty = fy - y0, tz = fz - z0;
    double sum = 0;
    for (int corner = 0; corner < 8; ++corner) {
      const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
      const Vec3i v{std::clamp(x0 + dx, box.begin.x, box.end.x - 1),
                    std::clamp(y0 + dy, box.begin.y, box.end.y - 1),
                    std::clamp(z0 + dz, box.begin.z, box.end.z - 1)};
      const double w = (dx ? tx : 1 - tx) * (dy ? ty : 1 - ty) * (dz ? tz : 1 - tz);
      sum += w * light_at_voxel(v);
    }
    return sum * s.light_inv_scale;
  }

  // Ambient occlusion: how much closer the nearest geometry is than it would be over an open
  // plane, at three points along the normal. Over a flat open face the field grows exactly as
  // s + 0.5 (voxel centres sit half a voxel behind the face), so open faces get no occlusion.
  double ambient_occlusion(const Vec3d& p, const Vec3d& n) const {
    static constexpr double kStep[3] = {0.5, 1.5, 3.0}, kWeight[3] = {0.5, 0.3, 0.2};
    double occlusion = 0;
    for (int i = 0; i < 3; ++i) {
      const double open = kStep[i] + 0.5;
      const double e = light_at(p + n * kStep[i]);
      occlusion += kWeight[i] * std::clamp((open - e) / open, 0.0, 1.0);
    }
    return std::clamp(1 - 1.7 * occlusion, 0.0, 1.0);
  }

  static Vec3d normal_of(const RayHit& h, const Vec3d& dir) {
    int axis = h.face_axis, sign = h.face_sign;
    if (axis < 0) {  // the ray started inside: face the viewer along its dominant axis
      axis = std::abs(dir.x) >= std::abs(dir.y) && std::abs(dir.x) >= std::abs(dir.z) ? 0
             : std::abs(dir.y) >= std::abs(dir.z)                                     ? 1
                                                                                      : 2;
      sign = dir[axis] > 0 ? -1 : 1;
    }
    Vec3d n;
    (axis == 0 ? n.x : axis == 1 ? n.y : n.z) = sign;
    return n;
  }

  // Whether a hit's shading reads a soft shadow (the sun reaches its face), and the ray that
  // finds it: towards the sun from just off the hit.
  bool wants_shadow(const RayHit& h, const Ray& ray) const {
    return o.soft_shadows && dot(normal_of(h, ray.direction), sun) > 0;
  }
  Ray shadow_ray(const RayHit& h, const Ray& ray) const {
    const Vec3d p = ray.origin + ray.direction * h.t;
    return {p + normal_of(h, ray.direction) * 1e-4, sun};
  }
  // The penumbra estimate min(k * clearance / t) taken over the voxels a shadow ray reads, the
  // clearance coming from the Euclidean field (its distance to the nearest solid voxel centre,
  // less the ~0.75 voxel a ray can pass from a voxel centre and a solid voxel's surface from its
  // own): `lit` so far, updated at voxel d.v of chunk `chunk`.
  double penumbra(double lit, const Dda& d, std::size_t chunk) const {
    if (d.t < kNear) return lit;
    const double e = s.light.read(chunk, s.table.brick_index(d.v)) * s.light_inv_scale;
    return std::min(lit, kSoftness * (e - 0.75) / d.t);
  }
  // The soft shadow: 0 when the shadow ray found a solid voxel (exact occlusion), else the
  // smoothed penumbra estimate.
  static double shadow_of(bool blocked, double lit) {
    if (blocked) return 0;
    lit = std::clamp(lit, 0.0, 1.0);
    return lit * lit * (3 - 2 * lit);
  }

  // The hit's colour in linear light given its soft shadow (1: none).
  Rgb shade(const RayHit& h, const Ray& ray, double shadow) const {
    const Vec3d n = normal_of(h, ray.direction);
    const Vec3d p = ray.origin + ray.direction * h.t;
    const auto& a = s.albedo[h.material];
    const Rgb albedo{a[0], a[1], a[2]};
    const double ndotl = std::max(0.0, dot(n, sun));
    const double ao = o.ambient_occlusion ? ambient_occlusion(p, n) : 1;
    const Rgb ambient = mix(kGround, kSkyAmbient, 0.5 + 0.5 * n.z) * (0.35 + 0.65 * ao);
    Rgb c = albedo * (kSunLight * (ndotl * shadow) + ambient);
    if (o.fog_density > 0)
      c = mix(c, sky(ray.direction, sky_scale), 1 - std::exp(-o.fog_density * h.t));
    return c;
  }

  // The chunks view's tint and grid lines over a hit's colour.
  void chunk_overlay(const RayHit& h, const Ray& ray, double footprint, Rgb& c) const {
    const Vec3d p = ray.origin + ray.direction * h.t;
    const double edge = s.table.chunk_edge();
    const double width = std::max(0.04, 0.75 * footprint);
    bool line = false;
    for (int a = 0; a < 3; ++a) {
      if (a == h.face_axis) continue;
      const double m = p[a] - edge * std::floor(p[a] / edge);
      line = line || std::min(m, edge - m) < width;
    }
    const bool dense = s.dense_material[s.table.chunk_index(h.voxel)] != 0;
    c = mix(c, dense ? Rgb{0.15, 0.35, 1.0} : Rgb{1.0, 0.55, 0.1}, 0.15);
    if (line) c = mix(c, Rgb{0.02, 0.02, 0.02}, 0.85);
  }
};

}  // namespace voxfield::render_detail
