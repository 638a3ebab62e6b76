// dynamicEDT3D peer for voxfield's incremental updates: the same world and the same seeded stream
// of sphere edits (as `voxfield bench edits`), applied to voxfield's DynamicDistanceField and to
// dynamicEDT3D (Lau, Sprunk & Burgard 2013; Debian libdynamicedt3d-dev) in one run, with the same
// Euclidean clamp. Per-edit latency (cell changes + update) is reported separately for
// placements and deletions, as medians, p99 and means (the mean is the total time of the same
// edits), with dynamicEDT3D / voxfield ratios.
//
// usage: edits_peer WORLD EDITS RADIUS_MIN RADIUS_MAX CLAMP THREADS OUT.json
#include <dynamicEDT3D/dynamicEDT3D.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <random>
#include <vector>

#include "voxfield/dynamic_field.h"
#include "voxfield/parallel.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

double ms(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

double pct(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1,
                    static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5))];
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / static_cast<double>(v.size());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 8) {
    std::fprintf(stderr,
                 "usage: edits_peer WORLD EDITS RADIUS_MIN RADIUS_MAX CLAMP THREADS OUT.json\n");
    return 2;
  }
  const int n = std::atoi(argv[1]), edits = std::atoi(argv[2]), rmin = std::atoi(argv[3]),
            rmax = std::atoi(argv[4]);
  const int clamp = std::atoi(argv[5]);
  ThreadLimit limit(std::atoi(argv[6]));
  SceneOptions so;
  so.size = Vec3i::splat(n);
  World world = make_terrain(so);

  // dynamicEDT3D wants a bool*** map (and takes ownership of it).
  std::vector<std::uint8_t> dense(static_cast<std::size_t>(n) * n * n);
  world.voxels.copy_to_dense(Box3i::from_size(so.size), dense.data());
  bool*** map = new bool**[n];
  for (int x = 0; x < n; ++x) {
    map[x] = new bool*[n];
    for (int y = 0; y < n; ++y) {
      map[x][y] = new bool[n];
      for (int z = 0; z < n; ++z)
        map[x][y][z] = dense[(static_cast<std::size_t>(z) * n + y) * n + x] != 0;
    }
  }
  auto t0 = std::chrono::steady_clock::now();
  DynamicEDT3D edt(clamp * clamp);
  edt.initializeMap(n, n, n, map);
  edt.update(true);
  auto t1 = std::chrono::steady_clock::now();
  const double peer_build = ms(t0, t1);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.max_distance = clamp;
  t0 = std::chrono::steady_clock::now();
  DynamicDistanceField field(world, o);
  t1 = std::chrono::steady_clock::now();
  const double vf_build = ms(t0, t1);

  // Pairs of edits at seeded random positions: a ball placed, then the same ball carved away, so
  // that insertions and deletions are measured in equal numbers (as dynamicEDT3D's own
  // evaluation does).
  std::mt19937_64 rng(6683787);
  auto uniform_int = [&](int lo, int hi) {
    return lo + static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
  };
  std::vector<double> vf_place, vf_carve, peer_place, peer_carve;
  DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kOccupancy);
  for (int i = 0; i < edits; ++i) {
    static int radius = 0;
    static Vec3i c;
    if (i % 2 == 0) {
      radius = uniform_int(rmin, rmax);
      c = {uniform_int(0, n - 1), uniform_int(0, n - 1), uniform_int(0, n - 1)};
    }
    const int material = i % 2 == 0 ? 1 + uniform_int(0, 254) : 0;
    Edit e;
    e.brush =
        SphereBrush{{static_cast<double>(c.x), static_cast<double>(c.y), static_cast<double>(c.z)},
                    static_cast<double>(radius)};
    e.op = material == 0 ? EditOp::kCarve : EditOp::kPlace;
    e.material = static_cast<std::uint8_t>(std::max(material, 1));
    // dynamicEDT3D: change the cells, then update.
    t0 = std::chrono::steady_clock::now();
    const Box3i box = brush_bounds(e.brush).intersect(Box3i::from_size(so.size));
    for (int z = box.begin.z; z < box.end.z; ++z)
      for (int y = box.begin.y; y < box.end.y; ++y)
        for (int x = box.begin.x; x < box.end.x; ++x) {
          if (!brush_contains(e.brush, {x, y, z})) continue;
          const bool occupied = edt.isOccupied(x, y, z);
          if (e.op == EditOp::kCarve && occupied) edt.clearCell(x, y, z);
          if (e.op == EditOp::kPlace && !occupied) edt.occupyCell(x, y, z);
        }
    edt.update(true);
    t1 = std::chrono::steady_clock::now();
    (e.op == EditOp::kCarve ? peer_carve : peer_place).push_back(ms(t0, t1));
    // voxfield.
    t0 = std::chrono::steady_clock::now();
    apply_edit(world, e, &dirty);
    field.update(dirty);
    dirty.clear();
    t1 = std::chrono::steady_clock::now();
    (e.op == EditOp::kCarve ? vf_carve : vf_place).push_back(ms(t0, t1));
  }
  std::printf(
      "world %d^3 terrain, %d sphere edits r %d..%d, Euclidean clamp %d, %d threads for voxfield\n",
      n, edits, rmin, rmax, clamp, max_threads());
  std::printf("build: voxfield %.1f ms, dynamicEDT3D %.1f ms\n", vf_build, peer_build);
  std::printf("%-10s %6s %12s %12s %13s %14s %14s %14s %10s %10s %10s\n", "edits", "count",
              "voxfield p50", "voxfield p99", "voxfield mean", "dynEDT3D p50", "dynEDT3D p99",
              "dynEDT3D mean", "p50 ratio", "p99 ratio", "mean ratio");
  auto row = [&](const char* what, const std::vector<double>& v, const std::vector<double>& d) {
    std::printf("%-10s %6zu %12.3f %12.3f %13.3f %14.3f %14.3f %14.3f %9.2fx %9.2fx %9.2fx\n", what,
                v.size(), pct(v, 0.5), pct(v, 0.99), mean(v), pct(d, 0.5), pct(d, 0.99), mean(d),
                pct(d, 0.5) / std::max(1e-9, pct(v, 0.5)),
                pct(d, 0.99) / std::max(1e-9, pct(v, 0.99)), mean(d) / std::max(1e-9, mean(v)));
  };
  row("place", vf_place, peer_place);
  row("carve", vf_carve, peer_carve);
  std::ofstream(argv[7]) << "{\"world\": " << n << ", \"edits\": " << edits
                         << ", \"radius_min\": " << rmin << ", \"radius_max\": " << rmax
                         << ", \"clamp\": " << clamp << ", \"threads\": " << max_threads()
                         << ", \"voxfield_place_p50\": " << pct(vf_place, 0.5)
                         << ", \"voxfield_place_p99\": " << pct(vf_place, 0.99)
                         << ", \"voxfield_carve_p50\": " << pct(vf_carve, 0.5)
                         << ", \"voxfield_carve_p99\": " << pct(vf_carve, 0.99)
                         << ", \"voxfield_place_mean\": " << mean(vf_place)
                         << ", \"voxfield_carve_mean\": " << mean(vf_carve)
                         << ", \"dynamicedt3d_place_mean\": " << mean(peer_place)
                         << ", \"dynamicedt3d_carve_mean\": " << mean(peer_carve)
                         << ", \"dynamicedt3d_place_p50\": " << pct(peer_place, 0.5)
                         << ", \"dynamicedt3d_place_p99\": " << pct(peer_place, 0.99)
                         << ", \"dynamicedt3d_carve_p50\": " << pct(peer_carve, 0.5)
                         << ", \"dynamicedt3d_carve_p99\": " << pct(peer_carve, 0.99) << "}\n";
  // dynamicEDT3D's destructor frees the map it was given.
}
