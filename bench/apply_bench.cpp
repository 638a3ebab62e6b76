// voxfield-bench-apply: the cost of applying brushes to a world (apply_edit alone, no field
// update), the first half of every edit. Pairs of "place, then carve the same brush" at seeded
// random positions in a generated terrain, so the world stays the same; prints mean / p50 / p99
// per edit and the voxels changed, per brush.
//
// usage: voxfield-bench-apply [WORLD_EDGE] [PAIRS]     (defaults 512 and 500)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "voxfield/edit.h"
#include "voxfield/scene.h"

using namespace voxfield;

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 512;
  const int pairs = argc > 2 ? std::atoi(argv[2]) : 500;
  if (n < 64 || pairs < 1) {
    std::fprintf(stderr, "usage: voxfield-bench-apply [WORLD_EDGE >= 64] [PAIRS >= 1]\n");
    return 2;
  }
  SceneOptions so;
  so.size = Vec3i::splat(n);
  World world = make_terrain(so);
  struct Case {
    std::string name;
    Brush (*make)(Vec3i c);
  };
  const Case cases[] = {
      {"sphere r 4",
       [](Vec3i c) -> Brush {
         return SphereBrush{{double(c.x), double(c.y), double(c.z)}, 4.0};
       }},
      {"sphere r 16",
       [](Vec3i c) -> Brush {
         return SphereBrush{{double(c.x), double(c.y), double(c.z)}, 16.0};
       }},
      {"sphere r 31",
       [](Vec3i c) -> Brush {
         return SphereBrush{{double(c.x), double(c.y), double(c.z)}, 31.0};
       }},
      {"box 21x13x10",
       [](Vec3i c) -> Brush {
         return BoxBrush{c, c + Vec3i{20, 12, 9}};
       }},
      {"rotated box 16x11x8",
       [](Vec3i c) -> Brush {
         return RotatedBoxBrush{{double(c.x), double(c.y), double(c.z)}, {8, 5.6, 4}, {10, 20, 30}};
       }},
  };
  std::printf("voxfield-bench-apply: terrain %d^3, %d place + carve pairs per brush\n", n, pairs);
  std::printf("%-22s %10s %10s %10s %16s\n", "brush", "mean us", "p50 us", "p99 us",
              "changed / edit");
  for (const Case& c : cases) {
    std::mt19937_64 rng(6683787);
    std::vector<double> us;
    std::int64_t changed = 0;
    for (int i = 0; i < pairs; ++i) {
      const Vec3i at{static_cast<int>(rng() % n), static_cast<int>(rng() % n),
                     static_cast<int>(rng() % n)};
      for (EditOp op : {EditOp::kPlace, EditOp::kCarve}) {
        const Edit e{op, c.make(at), 7};
        const auto t0 = std::chrono::steady_clock::now();
        changed += apply_edit(world, e).voxels_changed;
        us.push_back(
            std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0)
                .count());
      }
    }
    std::vector<double> sorted = us;
    std::sort(sorted.begin(), sorted.end());
    double sum = 0;
    for (double v : us) sum += v;
    std::printf("%-22s %10.1f %10.1f %10.1f %16.0f\n", c.name.c_str(), sum / us.size(),
                sorted[sorted.size() / 2],
                sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)],
                double(changed) / us.size());
  }
}
