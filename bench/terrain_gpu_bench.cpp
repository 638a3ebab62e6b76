// voxfield-bench-terrain-gpu: the reference thesis's GPU loop measured with voxfield's terrain
// renderer (gpu_terrain.h) — the field resident in i8, i16 or f32, classify + HistoPyramid + one
// indirect draw per frame, and after each edit only the samples it changed uploaded — in the
// counters that carry over from a software device to a real one: bytes up per edit and per frame,
// dispatches, draws, submits and fence waits per frame, bytes read back. The thesis re-sent the
// whole field every frame; that figure stands beside ours. Times on lavapipe are CPU emulation
// and are printed as such. Every frame's triangle count is checked against the CPU mesh of the
// same field (mesh_terrain), after the edits too.
//
// usage: voxfield-bench-terrain-gpu [EDGE] [EDITS] [RADIUS] [WIDTH] [HEIGHT]   (128 50 8 640 360)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench_gpu.h"
#include "bench_util.h"
#include "voxfield/error.h"
#include "voxfield/gpu_terrain.h"
#include "voxfield/mesh_render.h"

using namespace voxfield;

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 128;
  const int edits = argc > 2 ? std::atoi(argv[2]) : 50;
  const double radius = argc > 3 ? std::atof(argv[3]) : 8;
  const int width = argc > 4 ? std::atoi(argv[4]) : 640,
            height = argc > 5 ? std::atoi(argv[5]) : 360;
  if (n < 16 || edits < 1 || !(radius > 0) || width < 1 || height < 1) {
    std::fprintf(stderr,
                 "usage: voxfield-bench-terrain-gpu [EDGE >= 16] [EDITS >= 1] [RADIUS > 0] [WIDTH] "
                 "[HEIGHT]\n");
    return 2;
  }
  const std::shared_ptr<gpu::Context> ctx = bench::vulkan_device("voxfield-bench-terrain-gpu");
  if (!ctx) return 1;
  const gpu::DeviceInfo info = ctx->device();
  std::printf(
      "voxfield-bench-terrain-gpu: hills %d x %d x %d, %d smooth spheres of radius %.1f (blend 2), "
      "frames of %d x %d on %s%s\n\n",
      n, n, n / 2, edits, radius, width, height, info.name.c_str(),
      info.hardware ? "" : " (software: times are CPU emulation)");
  std::printf(
      "| storage | whole upload bytes | bytes up per edit mean / max | the thesis: whole field per "
      "frame | per frame: dispatches / draws / submits / fence waits | bytes up per frame | "
      "triangles | frame ms mean (%s) | GPU = CPU triangles "
      "|\n|---|---|---|---|---|---|---|---|---|\n",
      info.hardware ? "device" : "emulated");
  int status = 0;
  for (TerrainStorage storage : {TerrainStorage::kF32, TerrainStorage::kI16, TerrainStorage::kI8}) {
    TerrainOptions to;
    to.samples = {n, n, std::max(16, n / 2)};
    to.storage = storage;
    to.palette = default_palette();
    TerrainField terrain(to);
    const double h0 = 0.22 * n;
    terrain.assign(
        [&](const Vec3d& p) {
          return p.z - (h0 + 0.06 * n * std::sin(p.x / (n / 7.0)) * std::cos(p.y / (n / 5.0)));
        },
        1);
    gpu::TerrainRenderer renderer(ctx);
    const std::uint64_t whole = renderer.sync(terrain);
    MeshRenderOptions mo;
    mo.width = width;
    mo.height = height;
    const Camera camera =
        Camera::framing(Box3i::from_size(terrain.size()), static_cast<double>(width) / height);
    const gpu::TerrainView view = terrain_view(camera, mo);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0, 1);
    std::vector<double> sent, frame_ms;
    gpu::TerrainDrawStats frame{};
    bool equal = true;
    for (int e = 0; e < edits; ++e) {
      TerrainBrush b;
      b.mode = e % 2 ? TerrainBrush::Mode::kSubtract : TerrainBrush::Mode::kAdd;
      b.centre_units = {radius + u(rng) * (n - 2 * radius), radius + u(rng) * (n - 2 * radius),
                        h0 + 0.06 * n * (2 * u(rng) - 1)};
      b.radius_units = radius;
      b.smooth_units = 2;
      b.material = static_cast<std::uint8_t>(2 + e % 5);
      sent.push_back(static_cast<double>(renderer.sync(terrain, terrain.apply(b))));
      renderer.render(view, &frame);
      frame_ms.push_back(frame.ms);
    }
    const std::uint64_t cpu_triangles = mesh_terrain(terrain, MeshOptions{}).triangle_count();
    equal = frame.triangles == cpu_triangles;
    if (!equal) status = 1;
    double mean_sent = 0, max_sent = 0, mean_ms = 0;
    for (double s : sent)
      mean_sent += s / static_cast<double>(sent.size()), max_sent = std::max(max_sent, s);
    for (double m : frame_ms) mean_ms += m / static_cast<double>(frame_ms.size());
    const int per_sample = storage == TerrainStorage::kI8    ? 1
                           : storage == TerrainStorage::kI16 ? 2
                                                             : 4;
    const double field_bytes =
        static_cast<double>(Box3i::from_size(terrain.size()).volume()) * per_sample;
    std::printf(
        "| %s | %llu | %.0f / %.0f | %.0f | %lld / %lld / %lld / %lld | %lld | %llu | %.1f | %s "
        "|\n",
        terrain_storage_name(storage), static_cast<unsigned long long>(whole), mean_sent, max_sent,
        field_bytes, static_cast<long long>(frame.dispatches), static_cast<long long>(frame.draws),
        static_cast<long long>(frame.submits), static_cast<long long>(frame.fence_waits),
        static_cast<long long>(frame.bytes_uploaded),
        static_cast<unsigned long long>(frame.triangles), mean_ms, equal ? "yes" : "NO");
  }
  std::printf(
      "\nPer frame nothing is read back to draw: the %d x %d picture's %d bytes are read back for "
      "this benchmark only (a window presents them); bytes up per frame are the view's "
      "parameters.\n",
      width, height, 4 * width * height);
  return status;
}
