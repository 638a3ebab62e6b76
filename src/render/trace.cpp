// voxfield renderer — tracing single rays (the public entry point used by tests and tools).
#include "traverse.h"
#include "voxfield/error.h"

namespace voxfield {

const char* skip_mode_name(SkipMode m) {
  switch (m) {
    case SkipMode::kNone: return "none";
    case SkipMode::kChunks: return "chunks";
    case SkipMode::kDistance: return "distance";
  }
  return "?";
}

SkipMode parse_skip_mode(const std::string& name) {
  for (SkipMode m : {SkipMode::kNone, SkipMode::kChunks, SkipMode::kDistance})
    if (name == skip_mode_name(m)) return m;
  throw InvalidArgument("unknown skip mode \"" + name + "\" (expected none, chunks or distance)");
}

RayHit trace_ray(const RenderScene& scene, const Ray& ray, SkipMode mode, TraversalCounters* counters) {
  if (!(ray.direction.length() > 0) || !std::isfinite(ray.direction.length()) ||
      !std::isfinite(ray.origin.length()))
    throw InvalidArgument("trace_ray: the ray needs a finite origin and a non-zero finite direction");
  const RenderScene::Impl& s = scene.impl();
  TraversalCounters local;
  const RayHit hit = render_detail::traverse(s, s.box, ray, mode, s.skip, local,
                                             [](const render_detail::Dda&, std::size_t) {});
  if (counters) counters->add(local);
  return hit;
}

}  // namespace voxfield
