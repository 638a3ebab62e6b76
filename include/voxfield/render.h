// voxfield — CPU ray-marched rendering of voxel worlds through their distance fields.
//
// Primary rays walk the voxel grid with Amanatides & Woo's DDA ("A Fast Voxel Traversal Algorithm
// for Ray Tracing", Eurographics 1987) and skip ahead by the distance stored in an exact distance
// field, as the reference dissertation does with Manhattan fields; empty chunks are crossed in one
// step. Skipping never changes a result: the hit voxel and face are those of a plain DDA (see
// src/render/dda.h for why, tests/test_render.cpp for the test). Shading adds palette colour, sun
// and sky light, ambient occlusion and soft shadows from a Euclidean field, fog and a sky gradient.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "voxfield/algorithms.h"
#include "voxfield/distance.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/image.h"
#include "voxfield/interrupt.h"
#include "voxfield/world.h"

namespace voxfield {

// Rays in voxel coordinates: voxel v occupies the unit cube [v, v + 1).
struct Ray {
  Vec3d origin;
  Vec3d direction;  // need not be normalised; t is measured in multiples of it
};

struct Camera {
  enum class Projection { kPerspective, kOrthographic };
  Projection projection = Projection::kPerspective;
  Vec3d eye{0, 0, 0}, target{0, 0, -1}, up{0, 0, 1};  // z is up, as in MagicaVoxel
  double fov_degrees = 60;                            // perspective: vertical field of view
  double ortho_height = 1;  // orthographic: world units spanned by the image height
  // Set by in_voxels() for a frame whose voxels are not cubes: eye, target, up and ortho_height
  // are then in this frame's world coordinates, and projector() carries every ray into voxels.
  // Unset (every camera otherwise): they are in voxel coordinates.
  std::optional<VoxelFrame> world_frame;

  // Perspective view from above one corner, as close as keeps all eight corners of the box in
  // the image (3 % margin).
  static Camera framing(const Box3i& box, double aspect, double fov_degrees = 50);
  // Orthographic, looking down -z with +y up the image: the box's x and y extent fill the image
  // exactly along the limiting axis (both, when the aspect ratios agree), centred on the other.
  static Camera top(const Box3i& box, double aspect);
  // "top", "auto" or "eye=x,y,z:target=x,y,z[:up=x,y,z][:fov=deg][:ortho=height]" (ortho=
  // makes it orthographic). Throws InvalidArgument naming the bad part. `placed_in`, when given:
  // a placed camera's coordinates and heights are in that world frame (in_voxels, which may
  // refuse it); auto and top frame the box either way.
  static Camera parse(const std::string& spec, const Box3i& box, double aspect,
                      const VoxelFrame* placed_in = nullptr);
  // Whether parse() frames the box for `spec` ("auto", "top" or empty) rather than placing the
  // camera where the spec says: only a placed camera has a frame to be given in.
  static bool frames_the_box(const std::string& spec) {
    return spec.empty() || spec == "auto" || spec == "top";
  }

  // This camera given in the world frame of `frame` (eye, target and up in world coordinates,
  // the orthographic height in world units), as the renderer takes it: in voxel coordinates. A
  // rotation, a translation and one scale carry a pinhole camera onto a pinhole camera, so for
  // cubic voxels (equal to a part in 10^6) the result is a plain camera in voxels and the frame
  // drawn is the world's view exactly — the same rays, hits and pixels as a camera placed in
  // voxels by hand. Voxels that are not cubes (a scan's 1 x 1 x 3 mm) stretch the camera's image
  // axes in voxel space, which eye, target and up cannot say: the camera keeps its world
  // coordinates and the frame (world_frame), and its projector maps each ray into voxels — still
  // exactly the world's view. Throws InvalidArgument for a frame that validate() refuses, or for
  // a camera that already keeps a world_frame (a camera placed in cubic voxels is a plain camera
  // in voxels again: placing it twice carries it twice).
  Camera in_voxels(const VoxelFrame& frame) const;

  // Rays through the pixels of a width x height image, with the camera's basis computed once.
  struct Projector {
    Projection projection = Projection::kPerspective;
    // In voxel coordinates: an orthonormal basis, or (a camera with a world_frame) the world's
    // orthonormal basis carried into voxels, skewed and stretched by the voxels' shape.
    Vec3d eye, forward, right, up;
    double scale = 1;  // tan(fov / 2), or ortho_height / 2
    // What a ray's direction in voxels is multiplied by (then normalised) to look up the sky:
    // (1, 1, 1), or for a camera with a world_frame the voxels' world edge lengths — the world
    // ray's direction along the voxel axes, so non-cubic voxels do not bend the sky. (Its zenith
    // stays the voxels' z axis, as the sun stays in voxel terms, for every frame.)
    Vec3d sky_scale{1, 1, 1};
    int width = 1, height = 1;
    // The ray through (px, py) in pixels, (0, 0) the top-left corner: pixel centres are at +0.5.
    // Directions are unit vectors in voxel coordinates, so t measures voxels.
    Ray ray(double px, double py) const;
    // Voxels per unit of `scale`'s frame along the image's height: 1, or for a camera with a
    // world_frame the length of the mapped up (over the mapped forward's, perspective: t is
    // then voxels along a ray, the world's distance about t / |forward|).
    double footprint_scale = 1;
    // Size of one pixel, in voxels, at distance t along a ray: the chunk view's line width (for a
    // camera with a world_frame, along the image's height: its pixels are not squares in voxels).
    double footprint(double t) const {
      return (projection == Projection::kOrthographic ? 1 : t) * 2 * scale / height *
             footprint_scale;
    }
  };
  Projector projector(int width, int height) const;
  // The ray through the centre of pixel (px, py) of a width x height image (py = 0 at the top).
  Ray ray(int px, int py, int width, int height) const {
    return projector(width, height).ray(px + 0.5, py + 0.5);
  }
};

// How far rays may skip. kNone is the plain DDA that visits every voxel (the reference the
// skipping modes are tested against); kChunks skips empty chunks only; kDistance also skips by the
// distance field.
enum class SkipMode { kNone, kChunks, kDistance };
const char* skip_mode_name(SkipMode m);
SkipMode parse_skip_mode(const std::string& name);  // "none", "chunks", "distance"

struct RenderSceneOptions {
  // The field rays skip by. Manhattan is the dissertation's choice: k DDA steps stay within L1
  // distance k. Chebyshev and Euclidean fields are offered to measure the trade-off.
  Metric skip_metric = Metric::kManhattan;
  // Clamp of the skip field in voxels; 0 = as far as u8 storage reaches (255 voxels for
  // Manhattan and Chebyshev, 63 for Euclidean, stored in quarter voxels). A clamped field skips
  // less far in open space but follows edits locally: DynamicRenderScene wants 16-32.
  double skip_max_distance_vox = 0;
  // The Euclidean field behind ambient occlusion and soft shadows (clamped, u8 quarter voxels).
  bool lighting_field = true;
  double lighting_max_distance_vox = 16;
};

// Throws InvalidArgument, naming the option, for options every scene built with them would refuse
// (RenderScene, DynamicRenderScene, a device's scene): a check that builds no field, for a program
// that builds its scene later, or on a device only.
void check_render_scene_options(const RenderSceneOptions& options);

// A world prepared for rendering: the fields rays skip by and shade with, copied with the
// materials into a flat table of bricked chunks over the render box. A snapshot: edits to the
// world after construction are not seen. Keeps a reference to the world (for the error view's
// approximate field and the palette), which must outlive it.
class RenderScene {
 public:
  // Renders the voxels inside `box` (default: the world's bounds, else its content box).
  // Throws InvalidArgument for an empty box.
  explicit RenderScene(const World& world, const RenderSceneOptions& options = {},
                       std::optional<Box3i> box = std::nullopt);
  // Renders with fields the caller keeps (e.g. DynamicDistanceFields updated under edits): `skip`
  // unsigned u8 of any metric, `light` (optional) unsigned u8 Euclidean, both covering the box and
  // chunked like the world. Their values are copied; they need not outlive the scene. Throws
  // InvalidArgument for fields that do not fit.
  RenderScene(const World& world, const DistanceField& skip, const DistanceField* light,
              std::optional<Box3i> box = std::nullopt);
  ~RenderScene();
  RenderScene(RenderScene&&) noexcept;
  RenderScene& operator=(RenderScene&&) noexcept;

  // Brings the scene up to date after edits to its world: re-reads the materials and the fields'
  // values in every chunk of the render box that one of `boxes` touches — pass the edited boxes
  // grown by the fields' reach (DynamicDistanceField::reach()), or the boxes of the regions the
  // fields' updates recomputed. `skip` and `light` are as for the constructor taking fields, of the
  // scene's metric and scales, `light` given exactly when the scene has a lighting field; the
  // world's palette is re-read too. Cost proportional to the chunks touched, not the world. Returns
  // how many of them changed. Throws InvalidArgument for fields that do not fit.
  std::size_t update(const DistanceField& skip, const DistanceField* light,
                     std::span<const Box3i> boxes);

  const World& world() const;
  const Box3i& box() const;
  const RenderSceneOptions& options() const;
  // Milliseconds spent computing the fields (skip, lighting).
  double field_ms() const;

  struct Impl;
  const Impl& impl() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

// A world being edited and what rendering it needs, kept exact: the skip and lighting fields
// (DynamicDistanceFields, clamped so edits stay local) and a RenderScene that re-reads only the
// chunks an edit reaches. The world must outlive this object and be bounded (its bounds are the
// render box).
class DynamicRenderScene {
 public:
  // Throws InvalidArgument for an unbounded world or bad options (a skip clamp beyond u8's reach).
  explicit DynamicRenderScene(const World& world, RenderSceneOptions options = default_options());
  // skip_max_distance_vox 32 (Manhattan) — the showcase's and the demo's choice.
  static RenderSceneOptions default_options();

  struct UpdateStats {
    double field_ms = 0;  // both fields' incremental updates
    double scene_ms = 0;  // re-reading the chunks they reached
    std::int64_t voxels_recomputed = 0;
    std::size_t chunks_changed = 0;  // chunks of the scene whose contents changed
  };
  // Brings fields and scene up to date after the edits recorded in `dirty` (tracking every
  // material change, DirtyRegions::Track::kAnyChange, so that paint is seen). The caller clears
  // `dirty` afterwards.
  UpdateStats update(const DirtyRegions& dirty);

  const RenderScene& scene() const { return scene_; }
  const DistanceField& skip_field() const { return skip_.field(); }
  const DistanceField* light_field() const { return light_ ? &light_->field() : nullptr; }

 private:
  const World* world_;
  DynamicDistanceField skip_;
  std::optional<DynamicDistanceField> light_;
  RenderScene scene_;
};

struct RayHit {
  bool hit = false;
  Vec3i voxel{0, 0, 0};
  // Axis of the face the ray entered through (0, 1, 2) and its outward normal sign (+1, -1);
  // axis -1 when the ray starts inside a solid voxel.
  int face_axis = -1;
  int face_sign = 0;
  double t = 0;  // ray parameter at the entry point
  std::uint8_t material = 0;
};

// Work done by traversals, summed over rays.
struct TraversalCounters {
  std::int64_t rays = 0;
  std::int64_t steps = 0;        // DDA state changes (a bulk skip counts once)
  std::int64_t voxel_reads = 0;  // voxels whose material / distance was read
  // Empty chunks left in one step (with distance skips, primary rays leave them farther: through
  // the chunk's box extended by its smallest distance).
  std::int64_t chunk_skips = 0;
  // Skips of more than one voxel by the distance field: from an air voxel read, and for shadow
  // rays also out of an empty chunk when the distance's box reaches farther than the chunk's.
  std::int64_t distance_skips = 0;
  void add(const TraversalCounters& o) {
    rays += o.rays;
    steps += o.steps;
    voxel_reads += o.voxel_reads;
    chunk_skips += o.chunk_skips;
    distance_skips += o.distance_skips;
  }
};

// The first solid voxel along the ray (t >= 0) inside the scene's box.
RayHit trace_ray(const RenderScene& scene, const Ray& ray, SkipMode mode = SkipMode::kDistance,
                 TraversalCounters* counters = nullptr);

// The first solid voxel along the ray inside `box` (default: the world's bounds, else its content
// box, as RenderScene's), read from the world itself: the plain DDA, one voxel read per step, with
// no scene and no field to keep — for a pick under the cursor where the fields live elsewhere (on
// a device). The same hit as trace_ray() of a RenderScene of the world over the same box; a ray
// crosses at most the box's three sides' worth of voxels. Throws InvalidArgument for a degenerate
// ray or an empty box.
RayHit trace_ray(const World& world, const Ray& ray, std::optional<Box3i> box = std::nullopt);

// The same for many rays at once (hits[i] for rays[i]), multi-threaded — for ray casts that are
// not pictures (sensor simulation, visibility queries). Throws InvalidArgument when the spans
// differ in size or a ray is degenerate.
void trace_rays(const RenderScene& scene, std::span<const Ray> rays, std::span<RayHit> hits,
                SkipMode mode = SkipMode::kDistance, TraversalCounters* counters = nullptr);

enum class RenderView {
  kShaded,    // palette colour, sun, sky, ambient occlusion, soft shadows, fog
  kDistance,  // cut-away at slice_z: the skip field as a heat map on the cut, the world below it
  kError,     // |approximate - exact| along each ray; rays the approximation lets through
              // geometry in magenta (needs RenderOptions::error_algorithm)
  kChunks,    // shaded, with the chunk grid drawn on the surfaces and dense chunks tinted
};
const char* render_view_name(RenderView v);
RenderView parse_render_view(const std::string& name);  // "shaded", "distance", "error", "chunks"

struct RenderOptions {
  int width = 1280, height = 720;
  RenderView view = RenderView::kShaded;
  SkipMode skip = SkipMode::kDistance;
  bool ambient_occlusion = true;  // needs the scene's lighting field
  bool soft_shadows = true;       // needs the scene's lighting field
  double fog_density = 0;         // per voxel of travel; 0 = no fog
  // Direction towards the sun (normalised internally).
  Vec3d sun_direction{0.55, -0.35, 0.62};
  // kDistance: the cut plane (voxels above it are hidden). Default: the middle of the box.
  std::optional<int> slice_z;
  // kError: the approximation to show against the exact skip field.
  Algorithm error_algorithm = Algorithm::kJfa;
  int tile_size = 16;
};

struct RenderStats {
  double ms = 0;  // rendering only (fields, including the error view's approximation, excluded)
  int width = 0, height = 0;
  TraversalCounters primary, shadow;
  // kError: rays whose hit the approximate field changed (skipped through geometry), and the
  // largest |approximate - exact| met along any ray.
  std::int64_t rays_through_geometry = 0;
  double max_error = 0;
  double rays_per_second() const {
    return ms > 0 ? static_cast<double>(primary.rays) * 1000.0 / ms : 0;
  }
};

// Renders one frame. Multi-threaded over tiles; the image does not depend on the thread count or
// tile size. Throws InvalidArgument for bad options (size, a view that needs a field the scene
// lacks), Cancelled when `interrupter` asks (progress: tiles finished).
Image render(const RenderScene& scene, const Camera& camera, const RenderOptions& options,
             RenderStats* stats = nullptr, Interrupter* interrupter = nullptr);

}  // namespace voxfield
