// The debug visualiser of the paper (section 3.4): each pixel's ray is intersected with the
// volume's box (the slab method, in the box's own frame), then marched front to back through it,
// compositing an emission-absorption medium whose density follows the strength and whose colour
// follows the direction (|x|, |y|, |z| as red, green, blue), over a dark background.
#include <cmath>

#include "voxfield/error.h"
#include "voxfield/vectors.h"

namespace voxfield {
namespace {

std::uint8_t to_srgb8(double linear) {
  const double c = std::clamp(linear, 0.0, 1.0);
  const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::floor(s * 255.0 + 0.5));
}

}  // namespace

Image render_vectors(const VectorVolume& volume, const VectorTexture& texture,
                     const VectorViewOptions& view) {
  volume.validate();
  if (!(texture.resolution() == volume.resolution))
    throw InvalidArgument("render_vectors: the texture's resolution differs from the volume's");
  if (!(view.fov_deg > 1 && view.fov_deg < 179) || !(view.density > 0) ||
      !std::isfinite(view.density))
    throw InvalidArgument(
        "render_vectors: the field of view must be 1..179 degrees, the density > 0");
  Image image(view.width, view.height);
  const double diagonal = volume.size.length();
  const Vec3d eye = view.auto_eye ? volume.to_world({1.6, -0.9, 1.3}) : view.eye;
  const Vec3d forward = (volume.centre - eye).normalized();
  Vec3d up{0, 0, 1};
  if (std::abs(dot(up, forward)) > 0.99) up = {0, 1, 0};
  const Vec3d right = cross(forward, up).normalized();
  const Vec3d true_up = cross(right, forward);
  const double tan_half = std::tan(view.fov_deg * 3.14159265358979323846 / 360.0);
  const double aspect = static_cast<double>(view.width) / view.height;
  const Vec3d vs = volume.voxel_size();
  const double step = 0.5 * std::min({vs.x, vs.y, vs.z});
  const double density = view.density / diagonal;  // the box's diagonal at strength 1: opaque

  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x) {
      const double sx = (2.0 * (x + 0.5) / view.width - 1.0) * tan_half * aspect;
      const double sy = (1.0 - 2.0 * (y + 0.5) / view.height) * tan_half;
      const Vec3d dir = (forward + right * sx + true_up * sy).normalized();
      // Slab test in volume coordinates: the box is [0, 1]^3 there, the map is affine.
      const Vec3d o = volume.to_volume(eye), d = volume.to_volume(eye + dir) - o;
      double t0 = 0, t1 = 1e300;
      for (int a = 0; a < 3; ++a) {
        if (d[a] == 0) {
          if (o[a] < 0 || o[a] > 1) t1 = -1;
          continue;
        }
        double ta = (0 - o[a]) / d[a], tb = (1 - o[a]) / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      double r = 0.02, g = 0.025, b = 0.035;  // background
      if (t0 < t1) {
        double transmittance = 1, cr = 0, cg = 0, cb = 0;
        // Whole steps counted as integers (t += step stops advancing when t dwarfs step), at most
        // four per voxel along the longest path through the box.
        const Vec3i n = volume.resolution;
        const double span = std::min(t1 - t0, 4.0 * (n.x + n.y + n.z) * step);
        const std::int64_t steps = static_cast<std::int64_t>(std::ceil(span / step));
        for (std::int64_t k = 0; k < steps && transmittance > 0.004; ++k) {
          const double t = t0 + (static_cast<double>(k) + 0.5) * step;
          const VectorSample s = sample_vectors(volume, texture, eye + dir * t);
          if (s.strength <= 0) continue;
          const double alpha = 1 - std::exp(-density * s.strength * step);
          const double len = s.direction.length();
          const Vec3d c = len > 0 ? s.direction * (1.0 / len) : Vec3d{0.5, 0.5, 0.5};
          cr += transmittance * alpha * (0.15 + 0.85 * std::abs(c.x));
          cg += transmittance * alpha * (0.15 + 0.85 * std::abs(c.y));
          cb += transmittance * alpha * (0.15 + 0.85 * std::abs(c.z));
          transmittance *= 1 - alpha;
        }
        r = cr + transmittance * r;
        g = cg + transmittance * g;
        b = cb + transmittance * b;
      }
      std::uint8_t* px = image.pixel(x, y);
      px[0] = to_srgb8(r);
      px[1] = to_srgb8(g);
      px[2] = to_srgb8(b);
    }
  return image;
}

}  // namespace voxfield
