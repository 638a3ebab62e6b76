// voxfield — rasterising triangle meshes (mesh_render.h).
//
// Half-space rasterisation (Pineda, "A Parallel Algorithm for Polygon Rasterization", SIGGRAPH
// 1988): each triangle's pixels are those of its screen bounding box on the inner side of its three
// edge functions; barycentric weights come from the same functions. Depth is compared as the
// view-space depth interpolated perspective-correctly (1/z is linear in screen space); colours and
// normals are interpolated with the same weights. Both faces are lit (normals turned towards the
// viewer), so open sheets read correctly from either side.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "voxfield/error.h"
#include "voxfield/mesh_render.h"

namespace voxfield {

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
  const Camera::Projector pr = camera.projector(options.width, options.height);
  const bool ortho = pr.projection == Camera::Projection::kOrthographic;
  const double w = options.width, h = options.height;
  // Screen position (pixels, y down) and view depth of every vertex.
  struct Screen {
    double x, y, depth;
    bool visible;
  };
  std::vector<Screen> screen(mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const Vec3d d =
        Vec3d{mesh.positions[i][0], mesh.positions[i][1], mesh.positions[i][2]} - pr.eye;
    const double z = dot(d, pr.forward);
    double sx = dot(d, pr.right), sy = dot(d, pr.up);
    const bool visible = ortho || z > 1e-3;
    if (!ortho && visible) sx /= z, sy /= z;
    screen[i] = {(sx / pr.scale * h + w) / 2, (h - sy / pr.scale * h) / 2, z, visible};
  }
  const Vec3d light = options.light_towards.normalized();
  std::vector<float> depth(
      static_cast<std::size_t>(options.width) * static_cast<std::size_t>(options.height),
      std::numeric_limits<float>::infinity());
  MeshRenderStats st;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t* v = mesh.indices.data() + 3 * t;
    if (v[0] >= screen.size() || v[1] >= screen.size() || v[2] >= screen.size())
      throw InvalidArgument("render_mesh: index past the last vertex");
    const Screen &a = screen[v[0]], &b = screen[v[1]], &c = screen[v[2]];
    if (!a.visible || !b.visible || !c.visible) continue;  // crosses the eye plane: dropped
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
    ++st.triangles_drawn;
    // Edge lengths in pixels, for the distance of a pixel to each edge.
    const double len_a = std::hypot(c.x - b.x, c.y - b.y), len_b = std::hypot(a.x - c.x, a.y - c.y),
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
        Vec3d n{0, 0, 0};
        for (int k = 0; k < 3; ++k) {
          const double wk = k == 0 ? pa : k == 1 ? pb : pc;
          const auto& nk = mesh.normals[v[k]];
          n = n + Vec3d{nk[0], nk[1], nk[2]} * wk;
        }
        const double nl = n.length();
        n = nl > 0 ? n * (1 / nl) : Vec3d{0, 0, 1};
        // Light the face turned towards the viewer.
        if (dot(n, pr.ray(qx, qy).direction) > 0) n = n * -1;
        const double lambert = std::max(0.0, dot(n, light));
        const double shade = 0.28 + 0.72 * lambert;
        double rgb[3];
        for (int ch = 0; ch < 3; ++ch) {
          double base = options.base_color[static_cast<std::size_t>(ch)];
          if (options.use_colors && !mesh.colors.empty())
            base = pa * mesh.colors[v[0]][static_cast<std::size_t>(ch)] +
                   pb * mesh.colors[v[1]][static_cast<std::size_t>(ch)] +
                   pc * mesh.colors[v[2]][static_cast<std::size_t>(ch)];
          rgb[ch] = base * shade;
        }
        if (options.edges) {
          const double d = std::min({wa * std::abs(area) / len_a, wb * std::abs(area) / len_b,
                                     wc * std::abs(area) / len_c});
          if (d < 0.6)
            for (double& ch : rgb) ch *= 0.35;
        }
        std::uint8_t* out = image.pixel(px, py);
        for (int ch = 0; ch < 3; ++ch)
          out[ch] = static_cast<std::uint8_t>(std::min(255.0, std::max(0.0, rgb[ch]) + 0.5));
        ++st.pixels_covered;
      }
  }
  st.ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (stats) *stats = st;
  return image;
}

}  // namespace voxfield
