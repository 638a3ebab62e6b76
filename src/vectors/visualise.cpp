// The debug visualiser of the paper (section 3.4): each pixel's ray is intersected with the
// volume's box (the slab method, in the box's own frame), then marched front to back through it,
// compositing an emission-absorption medium whose density follows the strength and whose colour
// follows the direction (|x|, |y|, |z| as red, green, blue), over a dark background.
//
// The reactive sheet (VectorViewOptions::sheet) is a height field in the box's frame: at volume
// coordinates (x, y) its height is sheet_height + sheet_push * v_z / size_z, v_z the field's vector
// at the rest point along the box's z axis. The march looks for the first sample where the ray
// crosses it, refines the crossing by bisection, and stops there with the lit sheet's colour.
// vectors_view.comp draws the same picture on the GPU, in floats.
#include <cmath>

#include "vector_internal.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"
#include "voxfield/vectors.h"

namespace voxfield {
namespace {

std::uint8_t to_srgb8(double linear) {
  const double c = std::clamp(linear, 0.0, 1.0);
  const double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1 / 2.4) - 0.055;
  return static_cast<std::uint8_t>(std::floor(s * 255.0 + 0.5));
}

// The sheet of one picture: its rest height and its push, in volume coordinates.
struct Sheet {
  const VectorVolume& volume;
  const VectorTexture& texture;
  double rest, push;  // push: volume units of height per unit of the vector's z component

  // Height at volume coordinates (x, y), clamped to the box; `s` receives the sample there.
  double height(double x, double y, VectorSample* s = nullptr) const {
    const VectorSample v = sample_vectors(volume, texture, volume.to_world({x, y, rest}));
    if (s) *s = v;
    const Vec3d axis_z{volume.rotation[0][2], volume.rotation[1][2], volume.rotation[2][2]};
    return std::clamp(rest + push * dot(v.vector(), axis_z), 0.0, 1.0);
  }
  // Lit colour at the crossing (x, y): the normal from the height's slopes (in the box's frame,
  // scaled to world units), a fixed light from above, green tinted by the field's direction.
  Vec3d colour(double x, double y) const {
    const Vec3i n = volume.resolution;
    const double ex = 1.0 / n.x, ey = 1.0 / n.y;
    const double dx =
        (height(x + ex, y) - height(x - ex, y)) / (2 * ex) * volume.size.z / volume.size.x;
    const double dy =
        (height(x, y + ey) - height(x, y - ey)) / (2 * ey) * volume.size.z / volume.size.y;
    const Vec3d normal = Vec3d{-dx, -dy, 1}.normalized();
    const Vec3d light = Vec3d{0.4, 0.3, 1.0}.normalized();
    const double diffuse = std::abs(dot(normal, light));
    VectorSample s;
    height(x, y, &s);
    const double len = s.direction.length();
    const Vec3d tint = len > 0 ? s.direction * (1.0 / len) : Vec3d{0, 0, 0};
    const double w = std::clamp(s.strength, 0.0, 1.0);
    const Vec3d base{0.18, 0.42, 0.16};
    const Vec3d c{base.x + w * (0.15 + 0.85 * std::abs(tint.x) - base.x),
                  base.y + w * (0.15 + 0.85 * std::abs(tint.y) - base.y),
                  base.z + w * (0.15 + 0.85 * std::abs(tint.z) - base.z)};
    return c * (0.25 + 0.75 * diffuse);
  }
};

}  // namespace

namespace detail::vectors {

ViewCamera view_camera(const VectorVolume& v, const VectorViewOptions& view) {
  if (!(view.fov_deg > 1 && view.fov_deg < 179) || !(view.density > 0) ||
      !std::isfinite(view.density))
    throw InvalidArgument(
        "render_vectors: the field of view must be 1..179 degrees, the density > 0");
  if (view.width <= 0 || view.height <= 0 || view.width > 16384 || view.height > 16384)
    throw InvalidArgument("render_vectors: image size out of range (1..16384 per side)");
  if (view.sheet &&
      (!(view.sheet_height >= 0 && view.sheet_height <= 1) || !std::isfinite(view.sheet_push)))
    throw InvalidArgument("render_vectors: the sheet's height must be 0..1, its push finite");
  ViewCamera c;
  c.eye = view.auto_eye ? v.to_world({1.6, -0.9, 1.3}) : view.eye;
  const Vec3d target = view.look_at.value_or(v.centre);
  if (!((target - c.eye).length() > 0))
    throw InvalidArgument("render_vectors: the camera looks at its own position");
  c.forward = (target - c.eye).normalized();
  Vec3d up{0, 0, 1};
  if (std::abs(dot(up, c.forward)) > 0.99) up = {0, 1, 0};
  c.right = cross(c.forward, up).normalized();
  c.up = cross(c.right, c.forward);
  c.tan_half = std::tan(view.fov_deg * 3.14159265358979323846 / 360.0);
  c.aspect = static_cast<double>(view.width) / view.height;
  const Vec3d vs = v.voxel_size();
  c.step = 0.5 * std::min({vs.x, vs.y, vs.z});
  c.density = view.density / v.size.length();  // the box's diagonal at strength 1: opaque
  return c;
}

}  // namespace detail::vectors

Image render_vectors(const VectorVolume& volume, const VectorTexture& texture,
                     const VectorViewOptions& view) {
  volume.validate();
  if (!(texture.resolution() == volume.resolution))
    throw InvalidArgument("render_vectors: the texture's resolution differs from the volume's");
  const detail::vectors::ViewCamera cam = detail::vectors::view_camera(volume, view);
  Image image(view.width, view.height);
  const Vec3d eye = cam.eye, forward = cam.forward, right = cam.right, true_up = cam.up;
  const double tan_half = cam.tan_half, aspect = cam.aspect, step = cam.step, density = cam.density;
  const Sheet sheet{volume, texture, view.sheet_height, view.sheet_push / volume.size.z};

  // Rows are independent: each thread marches whole rows (four at least, so a hand-off costs less
  // than the rays it carries).
  parallel_for(static_cast<std::size_t>(view.height), 4, [&](std::size_t row0, std::size_t row1) {
    for (int y = static_cast<int>(row0); y < static_cast<int>(row1); ++y)
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
          // Above (> 0) or below the sheet at ray parameter t.
          auto side = [&](double t) {
            const Vec3d u = o + d * t;
            return u.z - sheet.height(u.x, u.y);
          };
          double last_t = t0, last_side = view.sheet ? side(t0) : 0;
          // Whole steps counted as integers (t += step stops advancing when t dwarfs step), at most
          // four per voxel along the longest path through the box.
          const Vec3i n = volume.resolution;
          const double span = std::min(t1 - t0, 4.0 * (n.x + n.y + n.z) * step);
          const std::int64_t steps = static_cast<std::int64_t>(std::ceil(span / step));
          for (std::int64_t k = 0; k < steps && transmittance > 0.004; ++k) {
            const double t = t0 + (static_cast<double>(k) + 0.5) * step;
            if (view.sheet) {
              const double now = side(t);
              if ((now > 0) != (last_side > 0)) {
                double lo = last_t, hi = t;  // the crossing lies between: bisect
                for (int i = 0; i < 8; ++i) {
                  const double mid = 0.5 * (lo + hi);
                  if ((side(mid) > 0) == (last_side > 0))
                    lo = mid;
                  else
                    hi = mid;
                }
                const Vec3d u = o + d * (0.5 * (lo + hi));
                const Vec3d c = sheet.colour(u.x, u.y);
                cr += transmittance * c.x;
                cg += transmittance * c.y;
                cb += transmittance * c.z;
                transmittance = 0;
                break;
              }
              last_t = t;
              last_side = now;
            }
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
  });
  return image;
}

}  // namespace voxfield
