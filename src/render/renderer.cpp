// voxfield renderer — frames: primary rays per pixel over tiles, shading and the debug views.
//
// Shading goes beyond the dissertation's colour x local occlusion (hit_shading.h): palette albedo
// in linear light, a sun with soft shadows and a sky dome with ambient occlusion, optional fog, and
// a sky gradient for misses.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

#include "hit_shading.h"
#include "ray_group.h"
#include "shading.h"
#include "traverse.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"

namespace voxfield {

const char* render_view_name(RenderView v) {
  switch (v) {
    case RenderView::kShaded:
      return "shaded";
    case RenderView::kDistance:
      return "distance";
    case RenderView::kError:
      return "error";
    case RenderView::kChunks:
      return "chunks";
  }
  return "?";
}

RenderView parse_render_view(const std::string& name) {
  for (RenderView v :
       {RenderView::kShaded, RenderView::kDistance, RenderView::kError, RenderView::kChunks})
    if (name == render_view_name(v)) return v;
  throw InvalidArgument("unknown view \"" + name +
                        "\" (expected shaded, distance, error or chunks)");
}

namespace {

using render_detail::Dda;
using render_detail::traverse;

using render_detail::Rgb;
using render_detail::sky;
using render_detail::tone_map;

using render_detail::heat;

struct Frame {
  const RenderScene::Impl& s;
  const RenderOptions& o;
  Camera::Projector projector;
  render_detail::HitShading light;
  const SkipSource* approx = nullptr;  // the error view's approximate field
  int slice_z = 0;
  double heat_max = 1;

  std::uint8_t skip_at(Vec3i v) const {
    return s.skip.distance(s.table.chunk_index(v), s.table.brick_index(v));
  }

  // The soft shadow of a hit: its shadow ray walked through the whole scene.
  double soft_shadow(const RayHit& h, const Ray& ray, TraversalCounters& c) const {
    double lit = 1;
    const RayHit blocker = traverse(
        s, s.box, light.shadow_ray(h, ray), SkipMode::kDistance, s.skip, c,
        [&](const Dda& d, std::size_t chunk) { lit = light.penumbra(lit, d, chunk); },
        /*samples_air=*/true);
    return render_detail::HitShading::shadow_of(blocker.hit, lit);
  }

  Rgb shade(const RayHit& h, const Ray& ray, bool shadows,
            TraversalCounters& shadow_counters) const {
    const double shadow =
        shadows && light.wants_shadow(h, ray) ? soft_shadow(h, ray, shadow_counters) : 1;
    return light.shade(h, ray, shadow);
  }

  void chunk_overlay(const RayHit& h, const Ray& ray, Rgb& c) const {
    light.chunk_overlay(h, ray, projector.footprint(h.t), c);
  }

  // The shaded view's (and the chunk view's) pixel for its primary ray's hit.
  void shaded_pixel(const Ray& ray, const RayHit& h, std::uint8_t* out, RenderStats& st) const {
    Rgb c = h.hit ? shade(h, ray, true, st.shadow) : sky(ray.direction, projector.sky_scale);
    if (h.hit && o.view == RenderView::kChunks) chunk_overlay(h, ray, c);
    tone_map().write(c, out);
  }

  // Pixels [x0, x1) of row y in the shaded or chunk view: the primary rays walked in groups whose
  // voxel reads overlap (ray_group.h), then shaded one by one.
  void shaded_row(Image& image, int y, int x0, int x1, RenderStats& st) const {
    Ray rays[render_detail::kRayGroup];
    RayHit hits[render_detail::kRayGroup];
    for (int x = x0; x < x1; x += render_detail::kRayGroup) {
      const int n = std::min(render_detail::kRayGroup, x1 - x);
      for (int i = 0; i < n; ++i) rays[i] = projector.ray(x + i + 0.5, y + 0.5);
      render_detail::traverse_group(s, s.box, rays, n, o.skip, s.skip, st.primary, hits);
      for (int i = 0; i < n; ++i) shaded_pixel(rays[i], hits[i], image.pixel(x + i, y), st);
    }
  }

  // A pixel of the distance or the error view (shaded_row() draws the other two).
  void pixel(int px, int py, std::uint8_t* out, RenderStats& st) const {
    const Ray ray = projector.ray(px + 0.5, py + 0.5);
    const auto noop = [](const Dda&, std::size_t) {};
    switch (o.view) {
      case RenderView::kShaded:
      case RenderView::kChunks:
        return;  // not drawn pixel by pixel
      case RenderView::kDistance: {
        Box3i cut = s.box;
        cut.end.z = slice_z + 1;
        Dda first;
        if (render_detail::start_in_box(cut, ray, first) && first.face_axis == 2 &&
            first.step[2] < 0 &&
            s.skip.material(s.table.chunk_index(first.v), s.table.brick_index(first.v)) == 0) {
          // The ray enters through the cut plane on an air voxel: show the field there, with a
          // darker band every 8 voxels of distance.
          ++st.primary.rays;
          render_detail::cut_plane_heat(skip_at(first.v), s.skip.inv_scale, heat_max, out);
          return;
        }
        const RayHit h = traverse(s, cut, ray, o.skip, s.skip, st.primary, noop);
        tone_map().write(
            h.hit ? shade(h, ray, false, st.shadow) : sky(ray.direction, projector.sky_scale), out);
        return;
      }
      case RenderView::kError: {
        // The plain DDA visits every voxel up to the true hit: the largest error on the way...
        double worst = 0;
        const RayHit exact =
            traverse(s, s.box, ray, SkipMode::kNone, s.skip, st.primary,
                     [&](const Dda& d, std::size_t chunk) {
                       const std::uint32_t b = s.table.brick_index(d.v);
                       const double e = s.skip.distance(chunk, b) * s.skip.inv_scale;
                       const double a = approx->distance(chunk, b) * approx->inv_scale;
                       worst = std::max(worst, std::abs(a - e));
                     });
        // ...and whether skipping by the approximate field still stops at that voxel.
        TraversalCounters unused;
        const RayHit skipped = traverse(s, s.box, ray, SkipMode::kDistance, *approx, unused, noop);
        st.max_error = std::max(st.max_error, worst);
        const Rgb c = exact.hit ? shade(exact, ray, false, st.shadow)
                                : sky(ray.direction, projector.sky_scale);
        const double grey = 0.8 * (0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b);
        tone_map().write({grey, grey, grey}, out);
        if (skipped.hit != exact.hit || skipped.voxel != exact.voxel) {
          ++st.rays_through_geometry;
          out[0] = 255;
          out[1] = 0;
          out[2] = 255;
        } else if (worst > 0) {
          // Logarithmic: errors of one step and of dozens of voxels both stay readable.
          std::uint8_t h[3];
          heat(std::log2(1 + worst) / 6, h);
          for (int ch = 0; ch < 3; ++ch)
            out[ch] = static_cast<std::uint8_t>((2 * out[ch] + 3 * h[ch]) / 5);
        }
        return;
      }
    }
  }
};

}  // namespace

namespace render_detail {

void check_frame_options(bool has_light, const RenderOptions& o) {
  if (o.width <= 0 || o.height <= 0 || o.width > 16384 || o.height > 16384)
    throw InvalidArgument("render: image size " + std::to_string(o.width) + "x" +
                          std::to_string(o.height) + " is out of range (1..16384 per side)");
  if (o.tile_size <= 0) throw InvalidArgument("render: tile size must be positive");
  if ((o.ambient_occlusion || o.soft_shadows) && !has_light)
    throw InvalidArgument(
        "render: ambient occlusion and soft shadows need the scene's lighting field "
        "(RenderSceneOptions::lighting_field)");
  if (!(o.fog_density >= 0)) throw InvalidArgument("render: fog density must be >= 0");
  if (!(o.sun_direction.length() > 0))
    throw InvalidArgument("render: the sun direction must be non-zero");
}

}  // namespace render_detail

Image render(const RenderScene& scene, const Camera& camera, const RenderOptions& o,
             RenderStats* stats, Interrupter* interrupter) {
  const RenderScene::Impl& s = scene.impl();
  render_detail::check_frame_options(s.has_light, o);

  Image image(o.width, o.height);
  const Camera::Projector projector = camera.projector(o.width, o.height);
  Frame f{s, o, projector, {s, o, o.sun_direction.normalized(), projector.sky_scale}};

  SkipSource approx;
  if (o.view == RenderView::kDistance) {
    f.slice_z = s.slice_z(o);
    f.heat_max = s.heat_max(f.slice_z);
  }
  if (o.view == RenderView::kError) {
    approx = s.approximation(o.error_algorithm);
    f.approx = &approx;
  }

  const int ts = o.tile_size;
  const int tiles_x = (o.width + ts - 1) / ts, tiles_y = (o.height + ts - 1) / ts;
  std::vector<RenderStats> tile_stats(static_cast<std::size_t>(tiles_x) * tiles_y);
  Progress progress(interrupter, "render", static_cast<std::int64_t>(tile_stats.size()));
  const auto t0 = std::chrono::steady_clock::now();
  parallel_for(tile_stats.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t tile = b; tile < e; ++tile) {
      if (progress.cancelled()) return;
      const int x0 = static_cast<int>(tile % tiles_x) * ts,
                y0 = static_cast<int>(tile / tiles_x) * ts;
      RenderStats& st = tile_stats[tile];
      const int x1 = std::min(x0 + ts, o.width);
      const bool shaded = o.view == RenderView::kShaded || o.view == RenderView::kChunks;
      for (int y = y0; y < std::min(y0 + ts, o.height); ++y) {
        if (shaded) {
          f.shaded_row(image, y, x0, x1, st);
          continue;
        }
        for (int x = x0; x < x1; ++x) f.pixel(x, y, image.pixel(x, y), st);
      }
      progress.advance();
    }
  });
  progress.throw_if_cancelled();
  if (stats) {
    RenderStats total;
    total.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    total.width = o.width;
    total.height = o.height;
    for (const RenderStats& t : tile_stats) {
      total.primary.add(t.primary);
      total.shadow.add(t.shadow);
      total.rays_through_geometry += t.rays_through_geometry;
      total.max_error = std::max(total.max_error, t.max_error);
    }
    *stats = total;
  }
  return image;
}

}  // namespace voxfield
