// voxfield renderer — frames relayed part by part across scenes (render_relay.h).
//
// Each part walks rays with the frame renderer's own traversal step (traverse.h's visit) inside its
// slab. Every walk, skips included, visits the plain DDA's voxels in the plain DDA's order with its
// times and faces (dda.h), so a part can start a primary ray where the plain DDA enters the part
// (Dda::leave of the box between the ray's entry into the whole box and the part) without waiting
// for the parts before it: all parts walk their stretches of every primary ray at once, and the
// first hit along the ray is the pixel's. A shadow ray that leaves the slab becomes a RayLeg
// carrying the DDA's state, which the next part resumes with Dda::start, its penumbra travelling
// along (the minimum over the voxels read is the same whichever part read them); it cannot start
// early, since its estimate depends on every voxel before.
//
// The distance view walks its primary rays through the box below the cut plane instead, and has no
// shadow rays: a ray that enters that box through the plane on an air voxel is the cut's pixel,
// drawn from the skip field there by the part that holds the plane's slice (nothing along the ray
// comes before its entry into the box).
#include "voxfield/render_relay.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>
#include <string>

#include "hit_shading.h"
#include "scene_impl.h"
#include "shading.h"
#include "traverse.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"

namespace voxfield {

using render_detail::Dda;
using render_detail::HitShading;
using render_detail::Rgb;
using render_detail::SkipWeights;
using render_detail::Step;

namespace {

// Ambient occlusion reads the lighting field at most 3 voxels along a hit face's normal, then the
// 8 voxel centres around that point: up to 4 slices beyond the hit's own part.
constexpr int kAmbientReachSlices = 4;

// `box` grown by `slices` along z, within `whole`.
Box3i grown_along_z(const Box3i& box, int slices, const Box3i& whole) {
  Box3i b = box;
  b.begin.z = std::max<std::int64_t>(whole.begin.z, std::int64_t{box.begin.z} - slices);
  b.end.z = std::min<std::int64_t>(whole.end.z, std::int64_t{box.end.z} + slices);
  return b;
}

void check_part(const Box3i& whole, const Box3i& part, int chunk_edge) {
  const auto on_chunk = [&](std::int32_t z, std::int32_t face) {
    return z == face || z % chunk_edge == 0;
  };
  if (part.empty() || !whole.contains(part) || part.begin.x != whole.begin.x ||
      part.begin.y != whole.begin.y || part.end.x != whole.end.x || part.end.y != whole.end.y ||
      !on_chunk(part.begin.z, whole.begin.z) || !on_chunk(part.end.z, whole.end.z))
    throw InvalidArgument("render: the part " + to_string(part) + " is not a slab of " +
                          to_string(whole) + " cut on chunk boundaries (edge " +
                          std::to_string(chunk_edge) +
                          "): the walks resume chunk by chunk (fewer parts or a smaller chunk "
                          "edge)");
}

// The part's scene: the box it reads (its slab and ambient occlusion's reach), the skip field as
// given when it covers that box (walks never read it beyond the slab), else its values over the
// slab with 0 (no skip) beyond, and a lighting field computed from the part's world.
RenderScene part_scene(const World& world, const Box3i& whole, const Box3i& part,
                       const DistanceField& skip, const RenderSceneOptions& options) {
  const DistanceOptions want = relay_skip_field_options(options, whole);
  if (skip.options.metric != want.metric || skip.options.storage != want.storage ||
      skip.options.max_distance != want.max_distance || skip.options.signed_distance)
    throw InvalidArgument("render: the part's skip field is not the scene's (" +
                          std::string(metric_name(want.metric)) + ", u8, clamped at " +
                          std::to_string(want.max_distance) + ")");
  if (!skip.domain.contains(part))
    throw InvalidArgument("render: the skip field's domain " + to_string(skip.domain) +
                          " does not cover the part " + to_string(part));
  const Box3i box = grown_along_z(part, kAmbientReachSlices, whole);
  std::optional<DistanceField> light;
  if (options.lighting_field) {
    light = compute_distance_field(
        world, light_field_options(options, relay_world_box(whole, part, options)));
  }
  if (skip.domain.contains(box))  // one part, or a skip field given beyond the slab: as it is
    return RenderScene(world, skip, light ? &*light : nullptr, box);
  // Else one copy of the skip values, over the scene's box.
  const auto& values = std::get<Grid<std::uint8_t>>(skip.values);
  DistanceField extended{skip.options,  box,
                         skip.encoding, values.rechunked(values.chunk_edge(), box),
                         std::nullopt,  skip.frame};
  auto& grid = std::get<Grid<std::uint8_t>>(extended.values);
  if (box.begin.z < part.begin.z) grid.fill({box.begin, {box.end.x, box.end.y, part.begin.z}}, 0);
  if (part.end.z < box.end.z) grid.fill({{box.begin.x, box.begin.y, part.end.z}, box.end}, 0);
  return RenderScene(world, extended, light ? &*light : nullptr, box);
}

}  // namespace

int relay_ghost_slices(const RenderSceneOptions& options) {
  if (!options.lighting_field) return kAmbientReachSlices;
  // The lighting field over the part and ambient occlusion's reach is exact when every site within
  // its clamp of those slices is in view (a site farther away reads as the clamp either way).
  (void)light_field_options(options, {});  // checks the clamp
  return kAmbientReachSlices + static_cast<int>(std::ceil(options.lighting_max_distance_vox));
}

Box3i relay_world_box(const Box3i& whole, const Box3i& part, const RenderSceneOptions& options) {
  return grown_along_z(part, relay_ghost_slices(options), whole);
}

namespace {

// The distance view's cut plane: RenderOptions::slice_z, by default the middle of the whole box
// (as RenderScene's, whose box the whole box is).
int relay_slice_z(const Box3i& whole, const RenderOptions& options) {
  const int z = options.slice_z ? *options.slice_z : (whole.begin.z + whole.end.z) / 2;
  if (z < whole.begin.z || z >= whole.end.z)
    throw InvalidArgument("render: slice z=" + std::to_string(z) + " lies outside the box " +
                          to_string(whole));
  return z;
}

}  // namespace

void check_relay_frame(const Box3i& whole, const Box3i& part, int chunk_edge,
                       const RenderSceneOptions& scene_options, const RenderOptions& options) {
  if (options.view == RenderView::kError)
    throw InvalidArgument(
        "render: the error view is not drawn part by part (shaded, chunks and distance are): the "
        "approximate algorithms it shows run on one process");
  check_part(whole, part, chunk_edge);
  if (options.view == RenderView::kDistance) (void)relay_slice_z(whole, options);
  (void)relay_skip_field_options(scene_options, whole);
  (void)relay_ghost_slices(scene_options);
  render_detail::check_frame_options(scene_options.lighting_field, options);
}

DistanceOptions relay_skip_field_options(const RenderSceneOptions& options, const Box3i& whole) {
  return skip_field_options(options, whole);
}

struct RelayFrame::Impl {
  Box3i whole, part;
  // The box primary rays walk (the whole box, or in the distance view the part of it below the cut
  // plane), and its part in this part's slab (can be empty).
  Box3i walk_box, walk_part;
  bool distance_view = false;
  int slice_z = 0;
  double heat_max = 1;  // the distance view's top of the heat ramp, if the slice is this part's
  RenderScene scene;
  RenderOptions o;
  Camera::Projector projector;
  HitShading light;
  std::vector<RayHit> hits;
  std::vector<RelayHit> candidates;  // this part's hit per pixel, for the pixel's first
  // The distance view: per pixel, the skip field's stored value where its ray enters the cut plane
  // on an air voxel of this part, else -1.
  std::vector<std::int16_t> cut_values;
  std::vector<double> shadow_ends;
  RenderStats stats;
  std::mutex merge;

  Impl(const World& world, const Box3i& whole_box, const Box3i& part_box, const DistanceField& skip,
       const RenderSceneOptions& scene_options, const Camera& camera, const RenderOptions& options)
      : whole(whole_box),
        part(part_box),
        walk_box(whole_box),
        walk_part(part_box),
        distance_view(options.view == RenderView::kDistance),
        scene(part_scene(world, whole_box, part_box, skip, scene_options)),
        o(options),
        projector(camera.projector(options.width, options.height)),
        light{scene.impl(), o, options.sun_direction.normalized(), projector.sky_scale} {
    if (!distance_view) return;
    slice_z = relay_slice_z(whole, o);
    walk_box.end.z = slice_z + 1;
    walk_part = part.intersect(walk_box);
    // The scene's box spans the whole box along x and y, so its slice is the whole box's.
    if (part.begin.z <= slice_z && slice_z < part.end.z) heat_max = scene.impl().heat_max(slice_z);
  }

  std::size_t pixels() const { return static_cast<std::size_t>(o.width) * o.height; }
  Ray primary_ray(std::uint32_t pixel) const {
    return projector.ray(pixel % static_cast<std::uint32_t>(o.width) + 0.5,
                         pixel / static_cast<std::uint32_t>(o.width) + 0.5);
  }
  static RayLeg leg_of(const Ray& ray, const Dda& d, std::uint32_t pixel, double lit) {
    RayLeg leg;
    leg.origin = ray.origin;
    leg.voxel = d.v;
    leg.t = d.t;
    leg.lit = lit;
    leg.pixel = pixel;
    leg.face_axis = static_cast<std::int8_t>(d.face_axis);
    return leg;
  }

  // The part's place along a ray (smaller first): parts are slabs along z, met in increasing z by
  // a ray rising and in decreasing z by one falling (one that keeps its z stays in one part).
  std::int32_t along(const Ray& ray) const {
    return ray.direction.z < 0 ? -part.begin.z : part.begin.z;
  }

  // Moves a primary ray's walk that entered the walk box outside the part to the voxel where the
  // plain DDA enters the part: leaving the box that reaches from dda's voxel to the part along z
  // and to the walk box's faces along x and y lands there, on the plain DDA's voxel, time and face
  // (dda.h). False when the ray moves away from the part or leaves the walk box first.
  bool enter_part(Dda& dda) const {
    int caps[3] = {0, 0, 0};
    if (dda.step[2] > 0 && dda.v.z < walk_part.begin.z) {
      caps[2] = walk_part.begin.z - dda.v.z - 1;
    } else if (dda.step[2] < 0 && dda.v.z >= walk_part.end.z) {
      caps[2] = dda.v.z - walk_part.end.z;
    } else {
      return false;
    }
    for (int a = 0; a < 2; ++a)
      caps[a] = dda.step[a] > 0 ? walk_box.end[a] - 1 - dda.v[a] : dda.v[a] - walk_box.begin[a];
    const Dda::Exit e = dda.exit_of(caps);
    if (e.axis != 2) return false;
    dda.leave(caps, e);
    return true;
  }

  // Walks a ray from dda's voxel (in the part: walk_part for a primary ray) until it hits, leaves
  // the whole box (the walk box, for a primary ray), or leaves the part for another (a shadow ray
  // then goes on as a leg in `out`; the part a primary ray goes on to walks it from there itself).
  void run(const Ray& ray, Dda& dda, std::uint32_t pixel, bool shadow, double lit,
           std::vector<RayLeg>& out, RenderStats& st) {
    const RenderScene::Impl& s = scene.impl();
    const SkipWeights sw(s.skip.metric, ray, /*samples_air=*/shadow);
    TraversalCounters& c = shadow ? st.shadow : st.primary;
    ++c.rays;  // a walk here: a ray relayed across parts counts once in each
    const auto on_air = [&](const Dda& d, std::size_t chunk) {
      if (shadow) lit = light.penumbra(lit, d, chunk);
    };
    RayHit hit;
    for (;;) {
      const Step step =
          render_detail::visit(s, shadow ? part : walk_part, shadow ? SkipMode::kDistance : o.skip,
                               s.skip, sw, dda, c, on_air, hit);
      if (step == Step::kContinue) continue;
      if (step == Step::kHit) {
        if (shadow) {
          shadow_ends[pixel] = HitShading::shadow_of(true, lit);
        } else {
          hits[pixel] = hit;
        }
      } else if (!shadow) {
        // Left the part (the next part walks the rest) or the whole box: no hit here.
      } else if (whole.contains(dda.v)) {
        out.push_back(leg_of(ray, dda, pixel, lit));
      } else {
        shadow_ends[pixel] = HitShading::shadow_of(false, lit);
      }
      return;
    }
  }

  // The pixel's first hit is here: the pixel is this part's to shade, and its shadow ray starts
  // here.
  void first_hit(std::uint32_t pixel, const Ray& ray, const RayHit& hit, std::vector<RayLeg>& out,
                 RenderStats& st) {
    if (distance_view || !light.wants_shadow(hit, ray)) {  // the distance view casts no shadows
      shadow_ends[pixel] = 1;
      return;
    }
    const Ray r = light.shadow_ray(hit, ray);
    Dda d;
    if (!render_detail::start_in_box(whole, r, d)) {
      shadow_ends[pixel] = HitShading::shadow_of(false, 1);
      return;
    }
    if (!part.contains(d.v)) {
      out.push_back(leg_of(r, d, pixel, 1));
      return;
    }
    run(r, d, pixel, true, 1, out, st);
  }

  // f(index, legs_out, stats) for indices in parallel; the legs and counters merged after.
  template <class F>
  std::vector<RayLeg> in_parallel(std::size_t n, F&& f) {
    std::vector<RayLeg> all;
    const auto t0 = std::chrono::steady_clock::now();
    parallel_for(n, 256, [&](std::size_t b, std::size_t e) {
      std::vector<RayLeg> out;
      RenderStats st;
      for (std::size_t i = b; i < e; ++i) f(i, out, st);
      const std::lock_guard<std::mutex> lock(merge);
      all.insert(all.end(), out.begin(), out.end());
      stats.primary.add(st.primary);
      stats.shadow.add(st.shadow);
    });
    stats.ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return all;
  }
};

RelayFrame::RelayFrame(const World& world, const Box3i& whole, const Box3i& part,
                       const DistanceField& skip, const RenderSceneOptions& scene_options,
                       const Camera& camera, const RenderOptions& options) {
  check_relay_frame(whole, part, world.voxels.chunk_edge(), scene_options, options);
  impl_ = std::make_unique<Impl>(world, whole, part, skip, scene_options, camera, options);
  impl_->hits.assign(impl_->pixels(), RayHit{});
  impl_->candidates.assign(impl_->pixels(), RelayHit{});
  if (impl_->distance_view) impl_->cut_values.assign(impl_->pixels(), -1);
  impl_->shadow_ends.assign(impl_->pixels(), std::numeric_limits<double>::infinity());
  impl_->stats.width = options.width;
  impl_->stats.height = options.height;
}

RelayFrame::~RelayFrame() = default;

const std::vector<RelayHit>& RelayFrame::start() {
  Impl& f = *impl_;
  (void)f.in_parallel(f.pixels(), [&](std::size_t i, std::vector<RayLeg>& out, RenderStats& st) {
    const auto pixel = static_cast<std::uint32_t>(i);
    const Ray ray = f.primary_ray(pixel);
    Dda d;
    if (!render_detail::start_in_box(f.walk_box, ray, d)) return;
    // The time the ray enters the walk box comes from the box's planes, its later events from the
    // DDA's formula, which can be an ulp earlier (a z crossing right after an entry through x or
    // y): no hit is ordered before it, so the part met first keeps a tie there too.
    const double entry_t = d.t;
    if (f.distance_view && d.face_axis == 2 && d.step[2] < 0 && f.part.contains(d.v)) {
      const RenderScene::Impl& s = f.scene.impl();
      const std::size_t chunk = s.table.chunk_index(d.v);
      const std::uint32_t brick = s.table.brick_index(d.v);
      if (s.skip.material(chunk, brick) == 0) {
        // In through the cut plane on air: the cut's pixel, first along the ray.
        ++st.primary.rays;
        f.cut_values[pixel] = s.skip.distance(chunk, brick);
        f.candidates[pixel] = {entry_t, f.along(ray)};
        return;
      }
    }
    // A ray in through the cut plane is the slice's part's alone: its cut pixel, or a hit on the
    // voxel it enters. The parts below need not walk it.
    if (f.distance_view && d.face_axis == 2 && d.step[2] < 0 && !f.part.contains(d.v)) return;
    if (f.walk_part.empty() || (!f.walk_part.contains(d.v) && !f.enter_part(d))) return;
    f.run(ray, d, pixel, false, 1, out, st);
    const RayHit& hit = f.hits[pixel];
    if (hit.hit) f.candidates[pixel] = {std::max(hit.t, entry_t), f.along(ray)};
  });
  return f.candidates;
}

std::vector<RayLeg> RelayFrame::start_shadows(std::span<const RelayHit> first) {
  Impl& f = *impl_;
  if (first.size() != f.pixels())
    throw InvalidArgument("render: " + std::to_string(first.size()) + " first hits for " +
                          std::to_string(f.pixels()) + " pixels");
  return f.in_parallel(f.pixels(), [&](std::size_t i, std::vector<RayLeg>& out, RenderStats& st) {
    RayHit& hit = f.hits[i];
    const bool cut = f.distance_view && f.cut_values[i] >= 0;
    if (!hit.hit && !cut) return;
    const RelayHit mine = f.candidates[i];
    if (first[i].t != mine.t || first[i].along != mine.along) {
      hit.hit = false;  // a part before this one along the ray hit first
      if (cut) f.cut_values[i] = -1;
      return;
    }
    if (cut) return;  // the cut's pixel: no shadow
    const auto pixel = static_cast<std::uint32_t>(i);
    f.first_hit(pixel, f.primary_ray(pixel), hit, out, st);
  });
}

std::vector<RayLeg> RelayFrame::walk(std::span<const RayLeg> legs) {
  Impl& f = *impl_;
  // Each pixel has one ray in flight at most (its shadow ray starts where its primary ray ended),
  // which is what lets the walks write their pixel's results in parallel.
  std::vector<std::uint8_t> taken(legs.empty() ? 0 : f.pixels(), 0);
  for (const RayLeg& leg : legs) {
    if (leg.pixel >= f.pixels() || !f.part.contains(leg.voxel) || leg.face_axis < -1 ||
        leg.face_axis > 2)
      throw InvalidArgument("render: a ray leg for pixel " + std::to_string(leg.pixel) + " at " +
                            to_string(leg.voxel) + " does not belong to the part " +
                            to_string(f.part));
    if (taken[leg.pixel]++)
      throw InvalidArgument("render: two ray legs for pixel " + std::to_string(leg.pixel));
  }
  return f.in_parallel(legs.size(), [&](std::size_t i, std::vector<RayLeg>& out, RenderStats& st) {
    const RayLeg& leg = legs[i];
    const Ray ray{leg.origin, f.light.sun};
    Dda d;
    d.start(ray, leg.voxel, leg.t, leg.face_axis);
    f.run(ray, d, leg.pixel, true, leg.lit, out, st);
  });
}

const std::vector<double>& RelayFrame::shadows() const {
  return impl_->shadow_ends;
}

std::vector<std::uint8_t> RelayFrame::shade(std::span<const double> shadow) const {
  const Impl& f = *impl_;
  if (shadow.size() != f.pixels())
    throw InvalidArgument("render: " + std::to_string(shadow.size()) + " shadows for " +
                          std::to_string(f.pixels()) + " pixels");
  std::vector<std::uint8_t> rgba(4 * f.pixels(), 0);
  parallel_for(f.pixels(), 256, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const RayHit& h = f.hits[i];
      if (f.distance_view && f.cut_values[i] >= 0) {
        render_detail::cut_plane_heat(static_cast<std::uint8_t>(f.cut_values[i]),
                                      f.scene.impl().skip.inv_scale, f.heat_max,
                                      rgba.data() + 4 * i);
        rgba[4 * i + 3] = 255;
        continue;
      }
      if (!h.hit) continue;
      const Ray ray = f.primary_ray(static_cast<std::uint32_t>(i));
      Rgb c = f.light.shade(h, ray, shadow[i]);
      if (f.o.view == RenderView::kChunks)
        f.light.chunk_overlay(h, ray, f.projector.footprint(h.t), c);
      render_detail::tone_map().write(c, rgba.data() + 4 * i);
      rgba[4 * i + 3] = 255;
    }
  });
  return rgba;
}

Image RelayFrame::finish(std::span<const std::uint8_t> rgba) const {
  const Impl& f = *impl_;
  if (rgba.size() != 4 * f.pixels())
    throw InvalidArgument("render: " + std::to_string(rgba.size()) + " bytes of RGBA for " +
                          std::to_string(f.pixels()) + " pixels");
  Image image(f.o.width, f.o.height);
  for (std::size_t i = 0; i < f.pixels(); ++i) {
    std::uint8_t* px = image.pixel(static_cast<int>(i % static_cast<std::size_t>(f.o.width)),
                                   static_cast<int>(i / static_cast<std::size_t>(f.o.width)));
    if (rgba[4 * i + 3] == 255) {
      for (int c = 0; c < 3; ++c) px[c] = rgba[4 * i + static_cast<std::size_t>(c)];
    } else {
      render_detail::tone_map().write(
          render_detail::sky(f.primary_ray(static_cast<std::uint32_t>(i)).direction,
                             f.projector.sky_scale),
          px);
    }
  }
  return image;
}

const RenderStats& RelayFrame::stats() const {
  return impl_->stats;
}

}  // namespace voxfield
