#include <chrono>
#include <cstdio>
#include "voxfield/distance.h"
#include "voxfield/parallel.h"
#include "voxfield/scene.h"
using namespace voxfield;
int main(int argc, char** argv) {
  int n = argc > 1 ? atoi(argv[1]) : 256;
  int threads = argc > 2 ? atoi(argv[2]) : 2;
  ThreadLimit lim(threads);
  for (const char* scene : {"spheres", "terrain"}) {
    SceneOptions so; so.size = Vec3i::splat(n);
    World w = make_scene(scene, so);
    for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
      DistanceOptions o; o.metric = m;
      double best = 1e9;
      for (int r = 0; r < 5; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        DistanceField f = compute_distance_field(w, o);
        double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        best = std::min(best, ms);
      }
      printf("%s %s %d^3 threads %d: %.1f ms  %.0f Mvox/s\n", scene, metric_name(m), n, threads, best, n*double(n)*n/best/1e3);
    }
  }
}
