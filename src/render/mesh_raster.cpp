// voxfield — rasterising triangle meshes (mesh_render.h).
//
// Half-space rasterisation (Pineda, "A Parallel Algorithm for Polygon Rasterization", SIGGRAPH
// 1988): each triangle's pixels are those of its screen bounding box on the inner side of its three
// edge functions; barycentric weights come from the same functions. Depth is compared as the
// view-space depth interpolated perspective-correctly (1/z is linear in screen space); colours and
// normals are interpolated with the same weights. Both faces are lit (normals turned towards the
// viewer), so open sheets read correctly from either side. Perspective triangles are clipped
// against the near plane first (Sutherland & Hodgman, "Reentrant Polygon Clipping", 1974, against
// that one plane): a triangle reaching behind the eye — ground running under the camera — is cut
// to its part in front, not dropped.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/mesh_render.h"

namespace voxfield {

namespace {

// A mesh is drawn in its own coordinates, through the camera's orthonormal basis: a camera placed
// in a frame of non-cubic voxels (Camera::world_frame) has none there.
Camera::Projector mesh_projector(const Camera& camera, const MeshRenderOptions& options,
                                 const char* what) {
  if (camera.world_frame)
    throw InvalidArgument(std::string(what) +
                          ": a camera placed in a world of non-cubic voxels draws voxels; give a "
                          "mesh's camera in the mesh's coordinates");
  return camera.projector(options.width, options.height);
}

}  // namespace

gpu::TerrainView terrain_view(const Camera& camera, const MeshRenderOptions& options) {
  if (options.edges)
    throw InvalidArgument(
        "the GPU terrain renderer does not draw triangle edges (use render_mesh)");
  const Camera::Projector pr = mesh_projector(camera, options, "the GPU terrain renderer");
  gpu::TerrainView v;
  v.width = options.width;
  v.height = options.height;
  v.perspective = pr.projection == Camera::Projection::kPerspective;
  v.eye = pr.eye;
  v.forward = pr.forward;
  v.right = pr.right;
  v.up = pr.up;
  v.scale = pr.scale;
  v.light_towards = options.light_towards;
  v.background = options.background;
  v.base_color = options.base_color;
  v.use_colors = options.use_colors;
  return v;
}

Image render_mesh(const Mesh& mesh, const Camera& camera, const MeshRenderOptions& options,
                  MeshRenderStats* stats) {
  const auto start = std::chrono::steady_clock::now();
  Image image(options.width, options.height);
  if (mesh.normals.size() != mesh.positions.size() ||
      (!mesh.colors.empty() && mesh.colors.size() != mesh.positions.size()))
    throw InvalidArgument("render_mesh: normals and colours do not match the positions");
  for (std::size_t i = 0; i < image.rgb.size(); i += 3)
    std::copy(options.background.begin(), options.background.end(),
              image.rgb.begin() + static_cast<std::ptrdiff_t>(i));
  const Camera::Projector pr = mesh_projector(camera, options, "render_mesh");
  const bool ortho = pr.projection == Camera::Projection::kOrthographic;
  const double w = options.width, h = options.height;
  // Every vertex in view space: along right, up and forward (the depth).
  std::vector<Vec3d> view(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3d d =
        Vec3d{mesh.positions[i][0], mesh.positions[i][1], mesh.positions[i][2]} - pr.eye;
    view[i] = {dot(d, pr.right), dot(d, pr.up), dot(d, pr.forward)};
  }
  // A corner of a triangle as drawn: its screen position (pixels, y down), view depth, normal and
  // colour (a mesh vertex's, or interpolated along an edge the near plane cuts).
  struct Corner {
    double x, y, depth;
    Vec3d normal;
    std::array<double, 3> color;
  };
  const bool colored = options.use_colors && !mesh.colors.empty();
  const auto corner = [&](const Vec3d& p, const Vec3d& normal, const std::array<double, 3>& color) {
    const double sx = ortho ? p.x : p.x / p.z, sy = ortho ? p.y : p.y / p.z;
    return Corner{(sx / pr.scale * h + w) / 2, (h - sy / pr.scale * h) / 2, p.z, normal, color};
  };
  const auto vertex_color = [&](std::uint32_t i) {
    std::array<double, 3> c;
    for (std::size_t ch = 0; ch < 3; ++ch)
      c[ch] = colored ? mesh.colors[i][ch] : options.base_color[ch];
    return c;
  };
  constexpr double kNear = 1e-3;  // view depth of the near plane, in world units
  const Vec3d light = options.light_towards.normalized();
  std::vector<float> depth(
      static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height),
      std::numeric_limits<float>::infinity());
  MeshRenderStats st;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t* v = mesh.indices.data() + 3 * t;
    if (v[0] >= view.size() || v[1] >= view.size() || v[2] >= view.size())
      throw InvalidArgument("render_mesh: index past the last vertex");
    // The triangle's part in front of the near plane: a polygon of up to four corners.
    Corner polygon[4];
    bool cut[4] = {};  // the corner is where an edge meets the near plane
    int corners = 0;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t i = v[k], j = v[(k + 1) % 3];
      const Vec3d &p = view[i], &q = view[j];
      const auto& ni = mesh.normals[i];
      const bool in_p = ortho || p.z > kNear, in_q = ortho || q.z > kNear;
      if (in_p) polygon[corners++] = corner(p, {ni[0], ni[1], ni[2]}, vertex_color(i));
      if (in_p != in_q) {  // the edge crosses the plane: its point there
        const double f = (kNear - p.z) / (q.z - p.z);
        const auto& nj = mesh.normals[j];
        const std::array<double, 3> ci = vertex_color(i), cj = vertex_color(j);
        cut[corners] = true;
        polygon[corners++] =
            corner(p + (q - p) * f,
                   Vec3d{ni[0], ni[1], ni[2]} +
                       (Vec3d{nj[0], nj[1], nj[2]} - Vec3d{ni[0], ni[1], ni[2]}) * f,
                   {ci[0] + (cj[0] - ci[0]) * f, ci[1] + (cj[1] - ci[1]) * f,
                    ci[2] + (cj[2] - ci[2]) * f});
      }
    }
    bool drawn = false;
    // Polygon edge k (corner k to k + 1) lies on a mesh edge unless it is the cut along the near
    // plane; the fan's diagonals lie on none. Only mesh edges are drawn as edges.
    auto mesh_edge = [&](int k) { return !(cut[k] && cut[(k + 1) % corners]); };
    for (int fan = 1; fan + 1 < corners; ++fan) {
      const Corner &a = polygon[0], &b = polygon[fan], &c = polygon[fan + 1];
      // The edges opposite a, b and c: b-c, c-a and a-b.
      const bool show[3] = {mesh_edge(fan), fan + 2 == corners && mesh_edge(corners - 1),
                            fan == 1 && mesh_edge(0)};
      const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
      if (area == 0 || !std::isfinite(area)) continue;
      // Bounds clamped in double before the casts: a vertex just in front of the eye projects
      // far off screen, beyond int.
      auto pixel = [](double v, int size) {
        return static_cast<int>(std::clamp(v, -1.0, static_cast<double>(size)));
      };
      const int x0 = std::max(0, pixel(std::floor(std::min({a.x, b.x, c.x})), options.width));
      const int x1 =
          std::min(options.width - 1, pixel(std::ceil(std::max({a.x, b.x, c.x})), options.width));
      const int y0 = std::max(0, pixel(std::floor(std::min({a.y, b.y, c.y})), options.height));
      const int y1 =
          std::min(options.height - 1, pixel(std::ceil(std::max({a.y, b.y, c.y})), options.height));
      if (x0 > x1 || y0 > y1) continue;
      drawn = true;
      // Edge lengths in pixels, for the distance of a pixel to each edge.
      const double len_a = std::hypot(c.x - b.x, c.y - b.y),
                   len_b = std::hypot(a.x - c.x, a.y - c.y),
                   len_c = std::hypot(b.x - a.x, b.y - a.y);
      for (int py = y0; py <= y1; ++py)
        for (int px = x0; px <= x1; ++px) {
          const double qx = px + 0.5, qy = py + 0.5;
          // Barycentric weights: each vertex's opposite edge function over the doubled area.
          const double wa = ((b.x - qx) * (c.y - qy) - (b.y - qy) * (c.x - qx)) / area;
          const double wb = ((c.x - qx) * (a.y - qy) - (c.y - qy) * (a.x - qx)) / area;
          const double wc = 1 - wa - wb;
          if (wa < 0 || wb < 0 || wc < 0) continue;
          double pa = wa, pb = wb, pc = wc;  // perspective-correct weights
          double z;
          if (ortho) {
            z = wa * a.depth + wb * b.depth + wc * c.depth;
          } else {
            const double inv = wa / a.depth + wb / b.depth + wc / c.depth;
            z = 1 / inv;
            pa = wa / a.depth * z, pb = wb / b.depth * z, pc = wc / c.depth * z;
          }
          float& zb = depth[static_cast<std::size_t>(py) * static_cast<std::size_t>(options.width) +
                            static_cast<std::size_t>(px)];
          if (!(z < zb)) continue;
          zb = static_cast<float>(z);
          Vec3d n = a.normal * pa + b.normal * pb + c.normal * pc;
          const double nl = n.length();
          n = nl > 0 ? n * (1 / nl) : Vec3d{0, 0, 1};
          // Light the face turned towards the viewer.
          if (dot(n, pr.ray(qx, qy).direction) > 0) n = n * -1;
          const double lambert = std::max(0.0, dot(n, light));
          const double shade = 0.28 + 0.72 * lambert;
          double rgb[3];
          for (std::size_t ch = 0; ch < 3; ++ch)
            rgb[ch] = (pa * a.color[ch] + pb * b.color[ch] + pc * c.color[ch]) * shade;
          if (options.edges) {
            constexpr double kFar = std::numeric_limits<double>::infinity();
            const double d = std::min({show[0] ? wa * std::abs(area) / len_a : kFar,
                                       show[1] ? wb * std::abs(area) / len_b : kFar,
                                       show[2] ? wc * std::abs(area) / len_c : kFar});
            if (d < 0.6)
              for (double& ch : rgb) ch *= 0.35;
          }
          std::uint8_t* out = image.pixel(px, py);
          for (int ch = 0; ch < 3; ++ch)
            out[ch] = static_cast<std::uint8_t>(std::min(255.0, std::max(0.0, rgb[ch]) + 0.5));
          ++st.pixels_covered;
        }
    }
    st.triangles_drawn += drawn;
  }
  st.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = st;
  return image;
}

}  // namespace voxfield
