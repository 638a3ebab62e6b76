// voxfield — frames of a world that no one process holds (voxfield-mpi render): each part of the
// world, a slab along z, walks its stretch of every primary ray, and walks the shadow rays that
// cross it, handing each on where it leaves.
//
// Sort-last compositing usually has every part draw its own image and keeps each pixel's nearest
// hit; shadows that one part casts on another are then lost, and a skipping ray's walk would depend
// on where it started. Here the walks follow the one walk through the whole world. A traversal is
// a function of its ray and of the DDA's state at the voxel it has reached (render/dda.h: every
// event time comes from one formula, never accumulated, and a skip lands where the plain DDA
// would), and that state is the voxel, the time the ray entered it and the face it crossed. A
// primary ray's first hit is the first solid voxel of the plain DDA's sequence, so every part walks
// its own stretch of every primary ray at once, from the state the plain DDA has where the ray
// enters the part; the hit that comes first along the ray is the pixel's. A shadow ray's penumbra
// depends on every voxel it read, so it is relayed: a part resumes it where the last one left it
// and visits exactly the voxels, skips included, that one walk visits. A pixel is shaded by the
// part where its primary ray first hit, with the shadow its shadow ray found wherever that ended.
// The frame equals render() of the whole world's scene byte for byte, for any cut into parts on
// chunk boundaries.
//
// One part's steps: start() its stretches of the primary rays, which gives its hit per pixel; then
// start_shadows() with every pixel's first hit (the minimum over the parts' RelayHits), then walk()
// the legs other parts hand over until no part has any left (each returns the legs that left its
// part, to be routed by their voxel's z), then shade() with every pixel's shadow, and finish() the
// frame from every part's shaded pixels. mpi.h's mpi::render runs them over the ranks of a job.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/render.h"
#include "voxfield/world.h"

namespace voxfield {

// A shadow ray's walk paused at the first voxel outside the part that walked it. Plain bytes (it
// crosses processes as they are).
struct RayLeg {
  Vec3d origin;                 // the shadow ray's origin, just off its pixel's hit
  double t = 0;                 // the ray parameter at which it entered `voxel`
  double lit = 1;               // the penumbra estimate so far
  Vec3i voxel;                  // where the walk resumes
  std::uint32_t pixel = 0;      // y * width + x
  std::int8_t face_axis = -1;   // the axis crossed to enter `voxel`
  std::uint8_t unused[7] = {};  // 64 bytes with no padding: every byte sent is set
};

// A part's hit for a pixel's primary ray: when the ray entered the hit voxel (its ray parameter, or
// the ray's entry into the whole box — the box below the cut in the distance view — if that is
// later: +inf for no hit in the part) and the part's place along the ray (smaller: met first).
// Ordered by t, then by place, the smallest over the parts is the pixel's first hit: two parts'
// hits can share a t where the ray crosses a voxel edge on their border (or within an ulp of its
// entry into the box, where the box's planes and the DDA's formula round apart), and the plain DDA
// enters the part it meets first first. The layout of MPI's MPI_DOUBLE_INT (mpi::render reduces it
// with MPI_MINLOC).
struct RelayHit {
  double t = std::numeric_limits<double>::infinity();
  std::int32_t along = 0;
};

// The slices beyond its part, on either side along z, that a part's world must hold (within the
// whole box): the lighting field's clamp and ambient occlusion's reach.
int relay_ghost_slices(const RenderSceneOptions& options);

// The box a part's world must hold: the part and relay_ghost_slices along z, within `whole`.
Box3i relay_world_box(const Box3i& whole, const Box3i& part, const RenderSceneOptions& options);

// What RelayFrame refuses before any field is computed (InvalidArgument): the error view, a
// distance view whose slice lies outside `whole`, a part that is not a slab of `whole` cut on chunk
// boundaries of `chunk_edge`, options render() or RenderScene refuse.
void check_relay_frame(const Box3i& whole, const Box3i& part, int chunk_edge,
                       const RenderSceneOptions& scene_options, const RenderOptions& options);

// The skip field RenderScene computes for the box `whole`, which every part reads over its own
// slab: computed elsewhere for the whole box (voxfield-mpi: over the ranks, exactly).
DistanceOptions relay_skip_field_options(const RenderSceneOptions& options, const Box3i& whole);

class RelayFrame {
 public:
  // One part of a frame of the box `whole` of a world. `part`: a slab of it (the whole x-y extent)
  // cut along z on the world's chunk boundaries (or at the box's faces). `world`: the voxels of
  // relay_world_box(whole, part, scene_options), kept alive by the caller; whole chunks are read
  // where they straddle the box's faces, so outside `whole` the world must hold what the whole
  // scene's world holds there (nothing, when `whole` bounds the content, as a file's extent does).
  // `skip`: a field of relay_skip_field_options(scene_options, whole) whose values over `part` are
  // the whole box's. The part's lighting field is computed here. Views: shaded, chunks and
  // distance (its rays walk the box below the cut plane, with no shadow rays, and the part holding
  // the plane's slice draws the cut). Throws InvalidArgument for the error view, a part that is not
  // such a slab, fields or options that do not fit (as render() and RenderScene do).
  RelayFrame(const World& world, const Box3i& whole, const Box3i& part, const DistanceField& skip,
             const RenderSceneOptions& scene_options, const Camera& camera,
             const RenderOptions& options);
  ~RelayFrame();
  RelayFrame(const RelayFrame&) = delete;
  RelayFrame& operator=(const RelayFrame&) = delete;

  // Walks every primary ray's stretch in `part`, from where the plain DDA through `whole` enters
  // it, whichever part the ray crossed before; returns this part's hit per pixel (y * width + x).
  const std::vector<RelayHit>& start();
  // Given every pixel's first hit (per pixel, the smallest of the parts' start() by t, then by
  // place), keeps the hits that are their pixel's first and starts their shadow rays; returns the
  // legs that left the part for another (InvalidArgument for a count that is not the pixels').
  std::vector<RayLeg> start_shadows(std::span<const RelayHit> first);
  // Resumes shadow legs whose voxel lies in `part`; returns the legs that left it
  // (InvalidArgument for a leg that is not this part's, names no pixel, or shares its pixel with
  // another).
  std::vector<RayLeg> walk(std::span<const RayLeg> legs);
  // Per pixel (y * width + x): the shadow of the pixels whose shadow ray ended in this part (1
  // where the hit here needs none), +inf elsewhere. Their minimum over the parts is every hit
  // pixel's shadow.
  const std::vector<double>& shadows() const;
  // Per pixel, RGBA: the colour of each pixel whose primary ray hit in this part (alpha 255), zero
  // elsewhere, given every pixel's shadow (the minimum of the parts' shadows()).
  std::vector<std::uint8_t> shade(std::span<const double> shadow) const;
  // The frame from the per-byte maximum of every part's shade(): the sky where no part hit.
  Image finish(std::span<const std::uint8_t> rgba) const;
  // What this part walked: rays and their steps, skips and reads (a ray counts once in each part
  // that walked a stretch of it, and only if it entered the whole box: render() counts every
  // pixel's; a primary ray's stretches past its first hit are walked too), and ms the time in
  // start(), start_shadows() and walk().
  const RenderStats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace voxfield
