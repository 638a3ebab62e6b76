// voxfield-bench-world-mesh-edits: a voxel world's surface kept through edits (WorldMeshChunks).
// The generated terrain world takes a stream of seeded sphere placements and carves on its
// surface; after each one the kept mesh's field (the exact signed Euclidean field, clamped at 3)
// is updated and the chunks it reaches re-meshed. Prints, per edit, the time to apply the edit to
// the world and to update the mesh (mean / p50 / p99) and the chunks re-meshed, beside meshing
// the edited world from scratch with mesh_world(); at the end checks the kept mesh against that.
//
// usage: voxfield-bench-world-mesh-edits [EDGE] [EDITS] [RADIUS] [CHUNK] [MESHER]  (256 200 4 32
// mc)
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench_util.h"
#include "voxfield/edit.h"
#include "voxfield/mesh_chunks.h"
#include "voxfield/scene.h"

using namespace voxfield;

namespace {

void report(const char* what, const std::vector<double>& v) {
  const bench::Spread s = bench::spread(v);
  std::printf("%-28s mean %8.3f ms   p50 %8.3f ms   p99 %8.3f ms\n", what, s.mean, s.p50, s.p99);
}

// The mesh's corners (positions, then normals), sorted: equal for meshes with the same vertices
// however they are numbered (the tests compare triangles; this is the benchmark's sanity check).
std::vector<std::array<float, 6>> corners(const Mesh& m) {
  std::vector<std::array<float, 6>> out(m.vertex_count());
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = {m.positions[i][0], m.positions[i][1], m.positions[i][2],
              m.normals[i][0],   m.normals[i][1],   m.normals[i][2]};
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 256;
  const int edits = argc > 2 ? std::atoi(argv[2]) : 200;
  const double radius = argc > 3 ? std::atof(argv[3]) : 4;
  const int chunk = argc > 4 ? std::atoi(argv[4]) : 32;
  const Mesher mesher = parse_mesher(argc > 5 ? argv[5] : "mc");
  if (n < 32 || edits < 1 || !(radius > 0) || chunk < 2) {
    std::fprintf(stderr,
                 "usage: voxfield-bench-world-mesh-edits [EDGE >= 32] [EDITS >= 1] [RADIUS > 0] "
                 "[CHUNK >= 2] [mc|sn|dc]\n");
    return 2;
  }
  SceneOptions so;
  so.size = Vec3i::splat(n);
  World world = make_terrain(so);
  MeshOptions mo;
  mo.algorithm = mesher;
  mo.chunk_edge = chunk;
  auto t0 = std::chrono::steady_clock::now();
  WorldMeshChunks kept(world, mo);
  const double first_ms = bench::ms_since(t0);
  std::vector<double> scratch_ms;
  for (int run = 0; run < 3; ++run) {
    t0 = std::chrono::steady_clock::now();
    const Mesh m = mesh_world(world, mo);
    scratch_ms.push_back(bench::ms_since(t0));
  }
  std::printf(
      "voxfield-bench-world-mesh-edits: terrain world %d^3, %s, chunks of %d, first kept mesh "
      "%.0f ms, mesh_world %.0f ms (median of 3); %d spheres of radius %.1f\n",
      n, mesher_name(mesher), chunk, first_ms, bench::spread(scratch_ms).p50, edits, radius);
  auto surface = [&](int x, int y) {  // the top solid voxel of column (x, y)
    for (int z = n - 1; z > 0; --z)
      if (world.voxels.get({x, y, z}) != 0) return z;
    return n / 2;
  };
  std::mt19937_64 rng(6683787);
  std::vector<double> apply_ms, update_ms, total_ms;
  std::size_t remeshed = 0;
  for (int e = 0; e < edits; ++e) {
    const int cx = static_cast<int>(rng() % static_cast<unsigned>(n)),
              cy = static_cast<int>(rng() % static_cast<unsigned>(n));
    Edit edit;
    edit.op = rng() % 2 == 0 ? EditOp::kPlace : EditOp::kCarve;
    edit.material = static_cast<std::uint8_t>(1 + rng() % 8);
    edit.brush = SphereBrush{
        {static_cast<double>(cx), static_cast<double>(cy), static_cast<double>(surface(cx, cy))},
        radius};
    DirtyRegions dirty(world.voxels.chunk_edge(), DirtyRegions::Track::kAnyChange);
    t0 = std::chrono::steady_clock::now();
    apply_edit(world, edit, &dirty);
    const double a = bench::ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    remeshed += kept.update(dirty).size();
    const double u = bench::ms_since(t0);
    apply_ms.push_back(a);
    update_ms.push_back(u);
    total_ms.push_back(a + u);
  }
  report("edit applied", apply_ms);
  report("field + re-mesh", update_ms);
  report("edit total", total_ms);
  const Vec3i count = kept.chunk_count();
  std::printf("chunks re-meshed per edit: %.1f of %d\n", static_cast<double>(remeshed) / edits,
              count.x * count.y * count.z);
  const Mesh mine = kept.merged(), full = mesh_world(world, mo);
  const bool same =
      mine.triangle_count() == full.triangle_count() && corners(mine) == corners(full);
  std::printf("kept mesh %s mesh_world of the edited world (%zu triangles)\n",
              same ? "equals" : "DIFFERS FROM", mine.triangle_count());
  return same ? 0 : 1;
}
