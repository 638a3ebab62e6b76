// voxfield renderer — tracing single rays and batches of them (the public entry points used by
// tests and tools; a batch walks its rays in groups whose voxel reads overlap, ray_group.h).
#include <algorithm>
#include <vector>

#include "ray_group.h"
#include "traverse.h"
#include "voxfield/error.h"
#include "voxfield/parallel.h"

namespace voxfield {

const char* skip_mode_name(SkipMode m) {
  switch (m) {
    case SkipMode::kNone:
      return "none";
    case SkipMode::kChunks:
      return "chunks";
    case SkipMode::kDistance:
      return "distance";
  }
  return "?";
}

SkipMode parse_skip_mode(const std::string& name) {
  for (SkipMode m : {SkipMode::kNone, SkipMode::kChunks, SkipMode::kDistance})
    if (name == skip_mode_name(m)) return m;
  throw InvalidArgument("unknown skip mode \"" + name + "\" (expected none, chunks or distance)");
}

namespace {

void check_ray(const Ray& ray) {
  const double d = ray.direction.length(), o = ray.origin.length();
  if (!(d > 0) || !std::isfinite(d) || !std::isfinite(o))
    throw InvalidArgument("trace_ray: a ray needs a finite origin and a non-zero finite direction");
}

}  // namespace

RayHit trace_ray(const RenderScene& scene, const Ray& ray, SkipMode mode,
                 TraversalCounters* counters) {
  check_ray(ray);
  const RenderScene::Impl& s = scene.impl();
  TraversalCounters local;
  const RayHit hit = render_detail::traverse(s, s.box, ray, mode, s.skip, local,
                                             [](const render_detail::Dda&, std::size_t) {});
  if (counters) counters->add(local);
  return hit;
}

RayHit trace_ray(const World& world, const Ray& ray, std::optional<Box3i> box) {
  check_ray(ray);
  if (!box) box = world.voxels.bounds() ? *world.voxels.bounds() : world.voxels.content_bounds();
  if (box->empty()) throw InvalidArgument("trace_ray: nothing to trace (empty box)");
  render_detail::Dda dda;
  if (!render_detail::start_in_box(*box, ray, dda)) return {};
  for (; box->contains(dda.v); dda.step_once())
    if (const std::uint8_t m = world.voxels.get(dda.v); m != 0)
      return render_detail::make_hit(dda, m);
  return {};
}

void trace_rays(const RenderScene& scene, std::span<const Ray> rays, std::span<RayHit> hits,
                SkipMode mode, TraversalCounters* counters) {
  if (hits.size() != rays.size()) throw InvalidArgument("trace_rays: as many hits as rays, please");
  for (const Ray& ray : rays) check_ray(ray);
  const RenderScene::Impl& s = scene.impl();
  constexpr std::size_t kGrain = 256;
  std::vector<TraversalCounters> parts((rays.size() + kGrain - 1) / kGrain);
  parallel_for(parts.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t part = b; part < e; ++part) {
      const std::size_t end = std::min(rays.size(), (part + 1) * kGrain);
      for (std::size_t i = part * kGrain; i < end; i += render_detail::kRayGroup) {
        const int n = static_cast<int>(std::min<std::size_t>(render_detail::kRayGroup, end - i));
        render_detail::traverse_group(s, s.box, rays.data() + i, n, mode, s.skip, parts[part],
                                      hits.data() + i);
      }
    }
  });
  if (counters)
    for (const TraversalCounters& p : parts) counters->add(p);
}

}  // namespace voxfield
