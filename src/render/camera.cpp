// voxfield renderer — cameras: perspective and orthographic projection, automatic framing of a box,
// and the CLI's camera strings.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/render.h"

namespace voxfield {
namespace {

Vec3d centre_of(const Box3i& box) {
  return {0.5 * (box.begin.x + box.end.x), 0.5 * (box.begin.y + box.end.y),
          0.5 * (box.begin.z + box.end.z)};
}

double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

Vec3d parse_vec(const std::string& key, const std::string& text) {
  std::vector<double> v;
  std::stringstream ss(text);
  std::string part;
  while (std::getline(ss, part, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(part, &used));
      if (used != part.size()) throw std::invalid_argument(part);
    } catch (const std::exception&) {
      throw InvalidArgument("camera: " + key + "=" + text + ": \"" + part + "\" is not a number");
    }
  }
  if (v.size() != 3)
    throw InvalidArgument("camera: " + key + "=" + text + ": expected three numbers x,y,z");
  // Bounded so that ray positions stay exactly representable next to voxel coordinates (the
  // supported range is 2^29; beyond about 2^40 the traversal's conversions to int lose meaning).
  for (double x : v)
    if (!std::isfinite(x) || std::abs(x) > 1e12) {
      throw InvalidArgument("camera: " + key + "=" + text +
                            ": each coordinate must be finite and within +-1e12");
    }
  return {v[0], v[1], v[2]};
}

double parse_number(const std::string& key, const std::string& text) {
  try {
    std::size_t used = 0;
    const double x = std::stod(text, &used);
    if (used == text.size() && std::isfinite(x)) return x;
  } catch (const std::exception&) {
  }
  throw InvalidArgument("camera: " + key + "=" + text + ": not a number");
}

}  // namespace

Camera Camera::framing(const Box3i& box, double aspect, double fov_degrees) {
  Camera c;
  c.projection = Projection::kPerspective;
  c.fov_degrees = fov_degrees;
  c.target = centre_of(box);
  c.up = {0, 0, 1};
  // From above the (-x, -y) corner, 30 degrees over the horizon: shows two sides and the top.
  const double azimuth = radians(-115), elevation = radians(30);
  const Vec3d to_eye{std::cos(elevation) * std::cos(azimuth),
                     std::cos(elevation) * std::sin(azimuth), std::sin(elevation)};
  const Vec3d forward = to_eye * -1;
  const Vec3d right = cross(forward, c.up).normalized();
  const Vec3d up = cross(right, forward);
  const double tan_v = std::tan(radians(fov_degrees) / 2), tan_h = tan_v * aspect;
  Vec3d corners[8];
  for (int k = 0; k < 8; ++k)
    corners[k] = {double(k & 1 ? box.end.x : box.begin.x), double(k & 2 ? box.end.y : box.begin.y),
                  double(k & 4 ? box.end.z : box.begin.z)};
  // The eye sits at target + to_eye * D. A corner (offset q from the target) is in view when
  // |q.right| <= tan_h (q.forward + D) and |q.up| <= tan_v (q.forward + D): linear in D, so the
  // closest distance that shows all eight corners is a maximum over them. Then the target slides
  // across the view to centre the projected box, and the distance is fitted again; three rounds
  // settle it. 3 % margin.
  double distance = 0;
  for (int round = 0; round < 3; ++round) {
    distance = 0;
    for (const Vec3d& corner : corners) {
      const Vec3d q = corner - c.target;
      distance = std::max(distance,
                          std::max(std::abs(dot(q, right)) / tan_h, std::abs(dot(q, up)) / tan_v) -
                              dot(q, forward));
    }
    double lo_x = 1e300, hi_x = -1e300, lo_y = 1e300, hi_y = -1e300;
    for (const Vec3d& corner : corners) {
      const Vec3d q = corner - c.target;
      const double depth = dot(q, forward) + distance;
      lo_x = std::min(lo_x, dot(q, right) / depth);
      hi_x = std::max(hi_x, dot(q, right) / depth);
      lo_y = std::min(lo_y, dot(q, up) / depth);
      hi_y = std::max(hi_y, dot(q, up) / depth);
    }
    c.target =
        c.target + right * (0.5 * (lo_x + hi_x) * distance) + up * (0.5 * (lo_y + hi_y) * distance);
  }
  c.eye = c.target + to_eye * (distance * 1.03);
  return c;
}

Camera Camera::top(const Box3i& box, double aspect) {
  Camera c;
  c.projection = Projection::kOrthographic;
  const Vec3d centre = centre_of(box);
  c.target = {centre.x, centre.y, static_cast<double>(box.begin.z)};
  c.eye = {centre.x, centre.y, static_cast<double>(box.end.z) + 1};
  c.up = {0, 1, 0};
  const double w = box.size().x, h = box.size().y;
  c.ortho_height = w / h > aspect ? w / aspect : h;
  return c;
}

Camera Camera::parse(const std::string& spec, const Box3i& box, double aspect,
                     const VoxelFrame* placed_in) {
  if (spec == "top") return top(box, aspect);
  if (frames_the_box(spec)) return framing(box, aspect);
  Camera c;
  bool has_eye = false, has_target = false;
  std::stringstream ss(spec);
  std::string part;
  while (std::getline(ss, part, ':')) {
    const auto eq = part.find('=');
    if (eq == std::string::npos)
      throw InvalidArgument("camera: \"" + part +
                            "\" is not key=value (keys: eye, target, up, fov, ortho)");
    const std::string key = part.substr(0, eq), value = part.substr(eq + 1);
    if (key == "eye") {
      c.eye = parse_vec(key, value);
      has_eye = true;
    } else if (key == "target") {
      c.target = parse_vec(key, value);
      has_target = true;
    } else if (key == "up") {
      c.up = parse_vec(key, value);
    } else if (key == "fov") {
      c.fov_degrees = parse_number(key, value);
      if (!(c.fov_degrees > 0 && c.fov_degrees < 180))
        throw InvalidArgument("camera: fov must lie in (0, 180) degrees");
    } else if (key == "ortho") {
      c.projection = Projection::kOrthographic;
      c.ortho_height = parse_number(key, value);
      if (!(c.ortho_height > 0)) throw InvalidArgument("camera: ortho height must be positive");
    } else {
      throw InvalidArgument("camera: unknown key \"" + key +
                            "\" (keys: eye, target, up, fov, ortho)");
    }
  }
  if (!has_eye || !has_target)
    throw InvalidArgument("camera: give both eye=x,y,z and target=x,y,z");
  const Vec3d forward = c.target - c.eye;
  if (forward.length() == 0) throw InvalidArgument("camera: eye and target coincide");
  if (cross(forward, c.up).length() <= 1e-9 * forward.length() * c.up.length())
    throw InvalidArgument("camera: up is parallel to the view direction (or zero)");
  return placed_in ? c.in_voxels(*placed_in) : c;
}

Camera Camera::in_voxels(const VoxelFrame& frame) const {
  if (world_frame) throw InvalidArgument("camera: already placed in a world's frame");
  frame.validate("camera: the world's frame");
  const Vec3d s = frame.voxel_size_world;
  // Equal to a part in 10^6: cubes, as a float pipeline's transform states them (a .vdb's
  // rotated matrix is rescued within 1e-5, VoxelFrame::from_matrix, and its columns' lengths then
  // differ in the eighth digit); the rays stay those of the world's camera within that.
  const double size = (s.x + s.y + s.z) / 3;
  Camera c = *this;
  if (std::abs(s.x - size) > 1e-6 * size || std::abs(s.y - size) > 1e-6 * size ||
      std::abs(s.z - size) > 1e-6 * size) {
    // Not cubes: the image axes, orthonormal in the world, are not in voxels (projector()).
    c.world_frame = frame;
    return c;
  }
  c.eye = frame.vox_from_world(eye);
  c.target = frame.vox_from_world(target);
  c.up = frame.vox_direction(up);  // a direction: no translation (its length does not matter)
  c.ortho_height = ortho_height / size;
  return c;
}

Camera::Projector Camera::projector(int width, int height) const {
  Projector p;
  p.projection = projection;
  p.eye = eye;
  p.forward = (target - eye).normalized();
  p.right = cross(p.forward, up).normalized();
  p.up = cross(p.right, p.forward);
  p.scale = projection == Projection::kOrthographic ? ortho_height / 2
                                                    : std::tan(radians(fov_degrees) / 2);
  p.width = width;
  p.height = height;
  if (world_frame) {
    // The world's camera, every ray carried into voxels by the frame's linear map M: a
    // perspective ray's direction M (forward + sx right + sy up) is built from the mapped basis
    // as the plain one is and then normalised; an orthographic ray starts at M's image of its
    // world origin and runs along M forward, normalised here so that t measures voxels.
    const VoxelFrame& f = *world_frame;
    p.eye = f.vox_from_world(eye);
    p.forward = f.vox_direction(p.forward);
    p.right = f.vox_direction(p.right);
    p.up = f.vox_direction(p.up);
    p.footprint_scale = projection == Projection::kOrthographic
                            ? p.up.length()
                            : p.up.length() / p.forward.length();
    if (projection == Projection::kOrthographic) p.forward = p.forward.normalized();
    p.sky_scale = f.voxel_size_world;
  }
  return p;
}

Ray Camera::Projector::ray(double px, double py) const {
  // Image-plane coordinates in units of the image half-height, y up.
  const double sx = (2 * px - width) / height * scale;
  const double sy = (height - 2 * py) / height * scale;
  if (projection == Projection::kOrthographic) return {eye + right * sx + up * sy, forward};
  return {eye, (forward + right * sx + up * sy).normalized()};
}

}  // namespace voxfield
