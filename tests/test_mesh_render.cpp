// The mesh rasteriser (mesh_render.h) against ray casting: every pixel whose centre ray hits a
// triangle (Möller & Trumbore's test, in double) is covered, and no other — up to the pixels a
// triangle's edge passes within a hair of. Ground running under the camera (triangles reaching
// behind the eye, clipped at the near plane) included.
#include <gtest/gtest.h>

#include <cmath>

#include "voxfield/mesh_render.h"
#include "voxfield/primitives.h"

namespace voxfield {
namespace mesh_render_test {  // named: unity builds merge the test files

// Whether the ray hits triangle (a, b, c) in front of its origin.
bool hits(const Ray& r, Vec3d a, Vec3d b, Vec3d c) {
  const Vec3d e1 = b - a, e2 = c - a, p = cross(r.direction, e2);
  const double det = dot(e1, p);
  if (std::abs(det) < 1e-14) return false;
  const Vec3d s = r.origin - a;
  const double u = dot(s, p) / det;
  if (u < 0 || u > 1) return false;
  const Vec3d q = cross(s, e1);
  const double v = dot(r.direction, q) / det;
  if (v < 0 || u + v > 1) return false;
  return dot(e2, q) / det > 1e-3;
}

Vec3d at(const std::array<float, 3>& p) {
  return {p[0], p[1], p[2]};
}

// Pixels where the picture and the ray casts disagree on coverage.
std::int64_t disagreements(const Mesh& mesh, const Camera& camera, MeshRenderOptions o,
                           std::int64_t* covered) {
  o.background = {0, 0, 0};
  o.base_color = {255, 255, 255};
  o.use_colors = false;
  o.light_towards = {0, 0, 1};
  const Image image = render_mesh(mesh, camera, o);
  const Camera::Projector pr = camera.projector(o.width, o.height);
  std::int64_t wrong = 0;
  *covered = 0;
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      const Ray r = pr.ray(x + 0.5, y + 0.5);
      bool hit = false;
      for (std::size_t t = 0; t < mesh.triangle_count() && !hit; ++t)
        hit = hits(r, at(mesh.positions[mesh.indices[3 * t]]),
                   at(mesh.positions[mesh.indices[3 * t + 1]]),
                   at(mesh.positions[mesh.indices[3 * t + 2]]));
      const std::uint8_t* p = image.pixel(x, y);
      const bool drawn = p[0] != 0 || p[1] != 0 || p[2] != 0;
      *covered += drawn;
      wrong += drawn != hit;
    }
  return wrong;
}

Mesh ground(double half) {
  Mesh m;
  m.positions = {{static_cast<float>(-half), static_cast<float>(-half), 0},
                 {static_cast<float>(half), static_cast<float>(-half), 0},
                 {static_cast<float>(half), static_cast<float>(half), 0},
                 {static_cast<float>(-half), static_cast<float>(half), 0}};
  m.normals.assign(4, {0, 0, 1});
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

TEST(MeshRender, GroundUnderTheCameraIsClippedNotDropped) {
  // Standing 2 units above a 200-unit ground, looking level: both triangles reach behind the eye.
  Camera c;
  c.eye = {0, 0, 2};
  c.target = {0, 10, 1.5};
  MeshRenderOptions o;
  o.width = 160;
  o.height = 90;
  std::int64_t covered = 0;
  const std::int64_t wrong = disagreements(ground(100), c, o, &covered);
  EXPECT_GT(covered, o.width * o.height / 3);  // the lower half and more is ground
  EXPECT_LE(wrong, o.width + o.height) << "pixels off the ray casts' coverage";
}

TEST(MeshRender, CoverageEqualsRayCastingOnAClosedMesh) {
  // A coarse sphere (an octahedron subdivided twice, pushed out) seen whole, then from inside it
  // (every triangle around the eye, many crossing the near plane).
  Mesh m;
  m.positions = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.indices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
  for (int level = 0; level < 2; ++level) {
    std::vector<std::uint32_t> next;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
      std::uint32_t mid[3];
      for (int e = 0; e < 3; ++e) {
        const Vec3d p =
            (at(m.positions[m.indices[t + e]]) + at(m.positions[m.indices[t + (e + 1) % 3]])) * 0.5;
        const Vec3d n = p.normalized();
        m.positions.push_back(
            {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)});
        mid[e] = static_cast<std::uint32_t>(m.positions.size() - 1);
      }
      const std::uint32_t a = m.indices[t], b = m.indices[t + 1], c = m.indices[t + 2];
      next.insert(next.end(), {a, mid[0], mid[2], mid[0], b, mid[1], mid[2], mid[1], c, mid[0],
                               mid[1], mid[2]});
    }
    m.indices = next;
  }
  for (auto& p : m.positions) {
    const Vec3d n = at(p).normalized() * 5;
    p = {static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z)};
  }
  m.normals = m.positions;
  MeshRenderOptions o;
  o.width = 120;
  o.height = 80;
  for (const Vec3d eye : {Vec3d{3, -14, 6}, Vec3d{0.5, -1, 0.3}}) {
    Camera c;
    c.eye = eye;
    c.target = {0, 0, 0};
    std::int64_t covered = 0;
    const std::int64_t wrong = disagreements(m, c, o, &covered);
    EXPECT_GT(covered, 500);
    EXPECT_LE(wrong, (o.width + o.height) / 2) << "eye " << eye.x << ", " << eye.y << ", " << eye.z;
  }
}

}  // namespace mesh_render_test
}  // namespace voxfield
