// voxfield-bench-scene-gpu: a changing world drawn on a Vulkan device two ways, in the counters
// that carry over from a software device to a real one. "host fields": the skip and lighting
// fields are updated on the CPU (DynamicRenderScene) and the re-read chunks' cells copied to the
// device (SceneRenderer::sync) — what the demo does. "device fields": the world's changed chunks
// go up once, both fields are updated on the device and the cells packed there
// (gpu::DeviceRenderScene), and only 8 bytes per packed chunk come back. Both follow the same
// seeded stream of sphere edits; after the stream, frames of both are compared pixel for pixel.
// Times on a software device (lavapipe) are CPU emulation and are printed as such.
//
// usage: voxfield-bench-scene-gpu [EDGE] [EDITS] [RADIUS]   (128 100 4; a terrain of EDGE^3)
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench_gpu.h"
#include "bench_util.h"
#include "voxfield/edit_stream.h"
#include "voxfield/error.h"
#include "voxfield/gpu_render.h"
#include "voxfield/image.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

struct PathStats {
  std::vector<double> up, down, submits, ms;
  std::int64_t build_up = 0, build_down = 0;
  double build_ms = 0;
};

void print_row(const char* name, const PathStats& p) {
  const auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return v.empty() ? 0.0 : s / static_cast<double>(v.size());
  };
  double max_up = 0;
  for (double x : p.up) max_up = std::max(max_up, x);
  std::printf("| %s | %lld / %lld | %.3f | %.0f / %.0f | %.0f | %.2f | %.3f |\n", name,
              static_cast<long long>(p.build_up), static_cast<long long>(p.build_down),
              p.build_ms / 1000, mean(p.up), max_up, mean(p.down), mean(p.submits), mean(p.ms));
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 128;
  const int edits = argc > 2 ? std::atoi(argv[2]) : 100;
  const int radius = argc > 3 ? std::atoi(argv[3]) : 4;
  if (n < 16 || edits < 1 || radius < 1) {
    std::fprintf(stderr,
                 "usage: voxfield-bench-scene-gpu [EDGE >= 16] [EDITS >= 1] [RADIUS >= 1]\n");
    return 2;
  }
  const std::shared_ptr<gpu::Context> ctx = bench::vulkan_device("voxfield-bench-scene-gpu");
  if (!ctx) return 1;
  const gpu::DeviceInfo info = ctx->device();
  SceneOptions so;
  so.size = Vec3i::splat(n);
  so.chunk_edge = 32;
  World host_world = make_terrain(so), device_world = make_terrain(so);
  const RenderSceneOptions ro = DynamicRenderScene::default_options();
  std::printf(
      "voxfield-bench-scene-gpu: terrain %d^3 (chunk 32), skip field Manhattan clamp %.0f, "
      "lighting clamp %.0f, %d sphere edits of radius 1..%d, on %s%s\n\n",
      n, ro.skip_max_distance_vox, ro.lighting_max_distance_vox, edits, radius, info.name.c_str(),
      info.hardware ? "" : " (software: times are CPU emulation)");

  PathStats host, device;
  auto t0 = std::chrono::steady_clock::now();
  gpu::Counters c0 = ctx->counters();
  DynamicRenderScene live(host_world, ro);
  gpu::SceneRenderer renderer(ctx);
  renderer.sync(live.scene());
  host.build_ms = bench::ms_since(t0);
  host.build_up = ctx->counters().bytes_uploaded - c0.bytes_uploaded;
  host.build_down = ctx->counters().bytes_downloaded - c0.bytes_downloaded;
  t0 = std::chrono::steady_clock::now();
  c0 = ctx->counters();
  gpu::DeviceRenderScene scene(ctx, device_world, ro);
  device.build_ms = bench::ms_since(t0);
  device.build_up = ctx->counters().bytes_uploaded - c0.bytes_uploaded;
  device.build_down = ctx->counters().bytes_downloaded - c0.bytes_downloaded;

  RandomEditStream stream(*host_world.voxels.bounds(), 6683787, 1, radius);
  for (int i = 0; i < edits; ++i) {
    const Edit e = stream.next();
    for (bool on_device : {false, true}) {
      World& w = on_device ? device_world : host_world;
      PathStats& p = on_device ? device : host;
      DirtyRegions dirty(32, DirtyRegions::Track::kAnyChange);
      apply_edit(w, e, &dirty);
      const gpu::Counters before = ctx->counters();
      const auto t = std::chrono::steady_clock::now();
      if (on_device) {
        scene.update(dirty);
      } else {
        live.update(dirty);
        renderer.sync(live.scene());
      }
      p.ms.push_back(bench::ms_since(t));
      const gpu::Counters after = ctx->counters();
      p.up.push_back(static_cast<double>(after.bytes_uploaded - before.bytes_uploaded));
      p.down.push_back(static_cast<double>(after.bytes_downloaded - before.bytes_downloaded));
      p.submits.push_back(static_cast<double>(after.submits - before.submits));
    }
  }
  std::printf(
      "| fields | build: bytes up / down | build s | per edit: bytes up mean / max | bytes down "
      "mean | submits mean | ms mean (%s) |\n|---|---|---|---|---|---|---|\n",
      info.hardware ? "device" : "CPU + emulated device");
  print_row("host fields, cells copied up", host);
  print_row("device fields, cells packed there", device);
  RenderOptions o;
  o.width = 320;
  o.height = 180;
  const Camera cam = Camera::framing(live.scene().box(), 16.0 / 9.0);
  const Image a = renderer.render(cam, o), b = scene.render(cam, o);
  const bool same = a.rgb == b.rgb;
  std::printf("\nframes after the stream: %s (image hash %016llx)\n",
              same ? "equal pixel for pixel" : "DIFFERENT",
              static_cast<unsigned long long>(content_hash(a)));
  return same ? 0 : 1;
}
