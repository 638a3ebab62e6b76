// voxfield-bench-mesh-edits: deformable terrain, the reference thesis's loop. The terrain's exact
// signed Euclidean field (a float volume) takes a stream of seeded smooth sphere edits on its
// surface — each blended in with a polynomial smooth minimum (add) or maximum (carve) of blend
// radius 2 — and after each one MeshChunks re-meshes the chunks it reaches. Prints, per edit, the
// time to write the field, to re-mesh, and both (mean / p50 / p99), and the chunks re-meshed; at
// the end checks the kept mesh against meshing the edited volume from scratch.
//
// usage: voxfield-bench-mesh-edits [EDGE] [EDITS] [RADIUS] [CHUNK] [MESHER]   (512 200 8 32 mc)
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench_util.h"
#include "voxfield/distance.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

// Inigo Quilez's polynomial smooth minimum with blend radius k.
float smooth_min(float a, float b, float k) {
  const float h = std::max(k - std::abs(a - b), 0.0f) / k;
  return std::min(a, b) - h * h * k * 0.25f;
}

void report(const char* what, const std::vector<double>& v) {
  const bench::Spread s = bench::spread(v);
  std::printf("%-28s mean %8.3f ms   p50 %8.3f ms   p99 %8.3f ms\n", what, s.mean, s.p50, s.p99);
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 512;
  const int edits = argc > 2 ? std::atoi(argv[2]) : 200;
  const double radius = argc > 3 ? std::atof(argv[3]) : 8;
  const int chunk = argc > 4 ? std::atoi(argv[4]) : 32;
  const Mesher mesher = parse_mesher(argc > 5 ? argv[5] : "mc");
  if (n < 32 || edits < 1 || !(radius > 0) || chunk < 2) {
    std::fprintf(stderr,
                 "usage: voxfield-bench-mesh-edits [EDGE >= 32] [EDITS >= 1] [RADIUS > 0] [CHUNK "
                 ">= 2] [mc|sn|dc]\n");
    return 2;
  }
  SceneOptions so;
  so.size = Vec3i::splat(n);
  const World world = make_terrain(so);
  DistanceOptions fo;
  fo.metric = Metric::kEuclidean;
  fo.signed_distance = true;
  fo.max_distance = 16;
  fo.domain = Box3i::from_size(so.size);
  const DistanceField field = compute_distance_field(world, fo);
  std::vector<float> values(static_cast<std::size_t>(fo.domain->volume()));
  std::get<Grid<float>>(field.values).copy_to_dense(*fo.domain, values.data());
  const ScalarVolume volume{so.size, values.data()};
  MeshOptions mo;
  mo.algorithm = mesher;
  mo.chunk_edge = chunk;
  auto t0 = std::chrono::steady_clock::now();
  MeshChunks chunks(volume, mo);
  std::printf(
      "voxfield-bench-mesh-edits: terrain %d^3, %s, chunks of %d, first mesh %.0f ms, %d smooth "
      "spheres of radius %.1f\n",
      n, mesher_name(mesher), chunk, bench::ms_since(t0), edits, radius);
  // Surface heights, to put each edit on the terrain.
  auto surface = [&](int x, int y) {
    for (int z = n - 1; z > 0; --z)
      if (values[static_cast<std::size_t>(x) +
                 static_cast<std::size_t>(n) *
                     (static_cast<std::size_t>(y) +
                      static_cast<std::size_t>(n) * static_cast<std::size_t>(z))] < 0)
        return z;
    return n / 2;
  };
  std::mt19937_64 rng(6683787);
  std::vector<double> write_ms, mesh_ms, total_ms;
  std::size_t remeshed = 0;
  const float k = 2;
  for (int e = 0; e < edits; ++e) {
    const int cx = static_cast<int>(rng() % static_cast<unsigned>(n)),
              cy = static_cast<int>(rng() % static_cast<unsigned>(n));
    const bool add = rng() % 2 == 0;
    const double cz = surface(cx, cy);
    const int r = static_cast<int>(std::ceil(radius + k)) + 1;
    const Box3i box = Box3i{{cx - r, cy - r, static_cast<int>(cz) - r},
                            {cx + r + 1, cy + r + 1, static_cast<int>(cz) + r + 1}}
                          .intersect(Box3i::from_size(so.size));
    t0 = std::chrono::steady_clock::now();
    for (int z = box.begin.z; z < box.end.z; ++z)
      for (int y = box.begin.y; y < box.end.y; ++y)
        for (int x = box.begin.x; x < box.end.x; ++x) {
          const double dx = x - cx, dy = y - cy, dz = z - cz;
          const float d = static_cast<float>(std::sqrt(dx * dx + dy * dy + dz * dz) - radius);
          float& v = values[static_cast<std::size_t>(x) +
                            static_cast<std::size_t>(n) *
                                (static_cast<std::size_t>(y) +
                                 static_cast<std::size_t>(n) * static_cast<std::size_t>(z))];
          v = add ? smooth_min(v, d, k)
                  : -smooth_min(-v, d, k);  // carve: the smooth maximum of v and -d
        }
    const double w = bench::ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    remeshed += chunks.update(volume, box).size();
    const double m = bench::ms_since(t0);
    write_ms.push_back(w);
    mesh_ms.push_back(m);
    total_ms.push_back(w + m);
  }
  report("field write", write_ms);
  report("re-mesh", mesh_ms);
  report("edit total", total_ms);
  std::printf("chunks re-meshed per edit: %.1f of %d\n", static_cast<double>(remeshed) / edits,
              chunks.chunk_count().x * chunks.chunk_count().y * chunks.chunk_count().z);
  // Against the same chunked driver from scratch, array for array (mesh_volume() gives the same
  // triangles numbered by row: mesh.h).
  const Mesh kept = chunks.merged(), fresh = MeshChunks(volume, mo).merged();
  const bool same = kept.positions == fresh.positions && kept.normals == fresh.normals &&
                    kept.indices == fresh.indices;
  std::printf("kept mesh %s a full re-mesh (%zu triangles)\n", same ? "equals" : "DIFFERS FROM",
              kept.triangle_count());
  return same ? 0 : 1;
}
