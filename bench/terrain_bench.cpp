// voxfield-bench-terrain: the reference thesis's storage question (Nässén & Leiborn 2019 compared
// chars with ints) answered for voxfield's terrain field: the same terrain (make_terrain's world,
// through its exact signed Euclidean field, or smooth rolling hills: a height map's first-order
// signed distance (z - h) / sqrt(1 + |grad h|^2), as terrain generators give) stored in i8, i16 and
// f32, then, per storage,
//  * memory: the field's bytes, its uniform chunks, a dense chunk's bytes;
//  * the first mesh (CPU, all chunks) and its triangles;
//  * a stream of seeded smooth-sphere edits on the surface (add or carve, blend radius 2): the
//    brush's time, the re-mesh of the chunks it reaches, both together (mean / p50 / p99);
//  * bytes a renderer uploads per edit, at most (the storage chunks the changed box meets, whole),
//    against the thesis's whole field per frame;
//  * the quantisation's effect on the mesh: every vertex of the i8 / i16 mesh evaluated in the f32
//    field (trilinear), which is its distance from the f32 surface to first order, in spacings;
// and checks that the kept chunk meshes equal a mesh of the edited field made from scratch.
//
// usage: voxfield-bench-terrain [EDGE] [EDITS] [RADIUS] [MESH_CHUNK] [MESHER] [hills|voxels]
//        (512 200 8 16 mc hills)
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
#include "voxfield/terrain.h"

using namespace voxfield;

namespace {

// The f32 field between samples (trilinear), at a position in sample units.
double trilinear(const std::vector<float>& f, int n, const std::array<float, 3>& p) {
  int i[3];
  double t[3];
  for (int a = 0; a < 3; ++a) {
    const double c = std::clamp(static_cast<double>(p[static_cast<std::size_t>(a)]), 0.0, n - 1.0);
    i[a] = std::min(static_cast<int>(c), n - 2);
    t[a] = c - i[a];
  }
  double v = 0;
  for (int c = 0; c < 8; ++c) {
    const int x = i[0] + (c & 1), y = i[1] + (c >> 1 & 1), z = i[2] + (c >> 2 & 1);
    const double w = ((c & 1) ? t[0] : 1 - t[0]) * ((c >> 1 & 1) ? t[1] : 1 - t[1]) *
                     ((c >> 2 & 1) ? t[2] : 1 - t[2]);
    v += w * f[static_cast<std::size_t>(x) +
               static_cast<std::size_t>(n) *
                   (static_cast<std::size_t>(y) +
                    static_cast<std::size_t>(n) * static_cast<std::size_t>(z))];
  }
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  const int n = argc > 1 ? std::atoi(argv[1]) : 512;
  const int edits = argc > 2 ? std::atoi(argv[2]) : 200;
  const double radius = argc > 3 ? std::atof(argv[3]) : 8;
  const int mesh_chunk = argc > 4 ? std::atoi(argv[4]) : 16;
  const Mesher mesher = parse_mesher(argc > 5 ? argv[5] : "mc");
  const std::string kind = argc > 6 ? argv[6] : "hills";
  if (n < 32 || edits < 1 || !(radius > 0) || mesh_chunk < 2 ||
      (kind != "hills" && kind != "voxels")) {
    std::fprintf(stderr,
                 "usage: voxfield-bench-terrain [EDGE >= 32] [EDITS >= 1] [RADIUS > 0] "
                 "[MESH_CHUNK >= 2] [mc|sn|dc] [hills|voxels]\n");
    return 2;
  }
  SceneOptions so;
  so.size = Vec3i::splat(n);
  std::vector<float> exact(static_cast<std::size_t>(Box3i::from_size(so.size).volume()));
  if (kind == "voxels") {
    const World world = make_terrain(so);
    DistanceOptions fo;
    fo.metric = Metric::kEuclidean;
    fo.signed_distance = true;
    fo.max_distance = 16;
    fo.domain = Box3i::from_size(so.size);
    const DistanceField field = compute_distance_field(world, fo);
    std::get<Grid<float>>(field.values).copy_to_dense(*fo.domain, exact.data());
  } else {
    constexpr double kTau = 6.283185307179586;
    const double a = kTau / (n / 2.3), b = kTau / (n / 3.1), c = kTau / (n / 5.7);
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const double h = n * (0.45 + 0.08 * std::sin(x * a) * std::cos(y * b) +
                              0.03 * std::sin((x + 2 * y) * c));
        const double hx = n * (0.08 * a * std::cos(x * a) * std::cos(y * b) +
                               0.03 * c * std::cos((x + 2 * y) * c));
        const double hy = n * (-0.08 * b * std::sin(x * a) * std::sin(y * b) +
                               0.06 * c * std::cos((x + 2 * y) * c));
        const double scale = 1 / std::sqrt(1 + hx * hx + hy * hy);
        for (int z = 0; z < n; ++z)
          exact[static_cast<std::size_t>(x) +
                static_cast<std::size_t>(n) *
                    (static_cast<std::size_t>(y) +
                     static_cast<std::size_t>(n) * static_cast<std::size_t>(z))] =
              static_cast<float>((z - h) * scale);
      }
  }
  const ScalarVolume volume{so.size, exact.data()};
  MeshOptions mo;
  mo.algorithm = mesher;
  mo.chunk_edge = mesh_chunk;
  std::printf(
      "voxfield-bench-terrain: terrain %d^3 (%s), %s, mesh chunks of %d, %d smooth spheres of "
      "radius %.1f (blend 2) per storage\n\n",
      n, kind == "hills" ? "smooth hills" : "make_terrain's voxels, exact signed Euclidean field",
      mesher_name(mesher), mesh_chunk, edits, radius);
  std::printf(
      "| storage | clamp | step | field bytes | uniform chunks | dense chunk bytes | first mesh ms "
      "| triangles | brush ms p50 / p99 | re-mesh ms p50 / p99 | edit total ms mean / p50 / p99 | "
      "bytes up per edit (mean) | whole field per frame | vertex error vs f32, spacings (mean / "
      "max) | kept = fresh |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::vector<float> f32_field;  // the f32 terrain, for the others' vertex error
  int status = 0;
  for (TerrainStorage storage : {TerrainStorage::kF32, TerrainStorage::kI16, TerrainStorage::kI8}) {
    TerrainOptions to;
    to.samples = so.size;
    to.storage = storage;
    TerrainField terrain(to);
    terrain.assign(volume, 1);
    const TerrainField::Memory memory = terrain.memory();
    const int sample_bytes = storage == TerrainStorage::kI8    ? 1
                             : storage == TerrainStorage::kI16 ? 2
                                                               : 4;
    const std::uint64_t chunk_bytes =
        static_cast<std::uint64_t>(to.chunk_edge) * to.chunk_edge * to.chunk_edge * sample_bytes;
    auto t0 = std::chrono::steady_clock::now();
    MeshChunks chunks(terrain, mo);
    const double first_ms = bench::ms_since(t0);
    const Mesh first = chunks.merged();
    double error_sum = 0, error_max = 0;
    if (storage == TerrainStorage::kF32) {
      f32_field.resize(exact.size());
      terrain.decode(Box3i::from_size(so.size), f32_field.data());
    } else {
      for (const auto& p : first.positions) {
        const double e = std::abs(trilinear(f32_field, n, p));
        error_sum += e;
        error_max = std::max(error_max, e);
      }
    }
    // The same seeded edits for every storage, on the surface (the top solid sample of a column).
    std::mt19937_64 rng(6683787);
    std::vector<double> brush_ms, mesh_ms, total_ms;
    double bytes_up = 0;
    for (int e = 0; e < edits; ++e) {
      const int cx = static_cast<int>(rng() % static_cast<unsigned>(n)),
                cy = static_cast<int>(rng() % static_cast<unsigned>(n));
      const bool add = rng() % 2 == 0;
      int cz = n / 2;
      for (int z = n - 1; z > 0; --z)
        if (terrain.value({cx, cy, z}) < 0) {
          cz = z;
          break;
        }
      TerrainBrush b;
      b.mode = add ? TerrainBrush::Mode::kAdd : TerrainBrush::Mode::kSubtract;
      b.centre_units = {static_cast<double>(cx), static_cast<double>(cy), static_cast<double>(cz)};
      b.radius_units = radius;
      b.smooth_units = 2;
      b.material = 2;
      t0 = std::chrono::steady_clock::now();
      const Box3i changed = terrain.apply(b);
      const double w = bench::ms_since(t0);
      t0 = std::chrono::steady_clock::now();
      chunks.update(terrain, changed);
      const double m = bench::ms_since(t0);
      brush_ms.push_back(w);
      mesh_ms.push_back(m);
      total_ms.push_back(w + m);
      if (!changed.empty()) {  // the storage chunks the changed box meets, uploaded whole
        std::int64_t touched = 1;
        for (int a = 0; a < 3; ++a)
          touched *= (changed.end[a] - 1) / to.chunk_edge - changed.begin[a] / to.chunk_edge + 1;
        bytes_up += static_cast<double>(touched) * static_cast<double>(chunk_bytes);
      }
    }
    const Mesh kept = chunks.merged(), fresh = mesh_terrain(terrain, mo);
    const bool same = kept.positions == fresh.positions && kept.indices == fresh.indices;
    status |= same ? 0 : 1;
    const bench::Spread bs = bench::spread(brush_ms), ms = bench::spread(mesh_ms),
                        ts = bench::spread(total_ms);
    char error[64] = "— (the reference)";
    if (storage != TerrainStorage::kF32)
      std::snprintf(error, sizeof error, "%.4f / %.4f",
                    error_sum / static_cast<double>(first.positions.size()), error_max);
    std::printf(
        "| %s | %.0f | %.5f | %.1f MB | %lld of %lld | %llu | %.0f | %zu | %.3f / %.3f | %.3f / "
        "%.3f | %.3f / %.3f / %.3f | %.0f kB | %.1f MB | %s | %s |\n",
        terrain_storage_name(storage), terrain.max_distance_units(), terrain.step_units(),
        static_cast<double>(memory.bytes) / 1e6, static_cast<long long>(memory.uniform_chunks),
        static_cast<long long>(memory.chunks), static_cast<unsigned long long>(chunk_bytes),
        first_ms, first.triangle_count(), bs.p50, bs.p99, ms.p50, ms.p99, ts.mean, ts.p50, ts.p99,
        bytes_up / edits / 1e3,
        static_cast<double>(so.size.x) * so.size.y * so.size.z * sample_bytes / 1e6, error,
        same ? "yes" : "NO");
    std::fflush(stdout);
  }
  return status;
}
