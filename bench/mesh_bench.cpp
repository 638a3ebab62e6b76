// voxfield-bench-mesh: the CPU meshers on a float volume as a library user calls them, in one
// process, after a warm-up: `mesh_volume` (a fresh Mesh each call: its arrays come from new pages
// the kernel must zero, as in a one-shot program such as `voxfield mesh`) and `mesh_volume_into`
// into arrays allocated once and reused (as a game re-meshing every frame, or
// fast-surface-nets-rs's reused buffer, calls it). The difference between the two is the output's
// cost: allocating, zero-filling and freeing its arrays, of which the kernel's zeroing of their
// new pages is most.
//
// usage: voxfield-bench-mesh VOLUME.npy [--runs N] [--threads T] [--algorithms mc,sn,dc]
// Prints one Markdown row per mesher and path: median / min of N runs, triangles, vertices,
// ns per cell per thread, M triangles/s.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "bench_util.h"
#include "voxfield/mesh.h"
#include "voxfield/npy.h"
#include "voxfield/parallel.h"

using namespace voxfield;

namespace {

void print_row(const std::string& volume, const char* mesher, const char* path, int threads,
               const bench::Timing& t, const MeshCounts& counts, double cells) {
  const double triangles = static_cast<double>(counts.indices) / 3;
  std::printf("| %s | %s | %s | %d | %.1f | %.1f | %.0f | %zu | %.1f | %.1f |\n", volume.c_str(),
              mesher, path, threads, t.median_ms, t.min_ms, triangles, counts.vertices,
              t.median_ms * 1e6 * threads / cells, triangles / (t.median_ms * 1e3));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"voxfield-bench-mesh: fresh and reused-output meshing of a float volume"};
  std::string in, algorithms = "mc,sn,dc";
  int runs = 5, threads = 1;
  app.add_option("volume", in, "a float .npy volume")->required();
  app.add_option("--runs", runs, "timed runs after one warm-up")->check(CLI::Range(1, 1000));
  app.add_option("--threads", threads, "threads")->check(CLI::Range(1, 1024));
  app.add_option("--algorithms", algorithms, "comma-separated meshers: mc, sn, dc");
  CLI11_PARSE(app, argc, argv);
  try {
    const NpyVolume npy = read_npy(in);
    std::vector<float> values(static_cast<std::size_t>(npy.count()));
    for (std::int64_t i = 0; i < npy.count(); ++i)
      values[static_cast<std::size_t>(i)] = static_cast<float>(npy.value(i));
    const ScalarVolume volume{npy.dims, values.data()};
    const double cells = static_cast<double>(npy.dims.x - 1) * (npy.dims.y - 1) * (npy.dims.z - 1);
    const std::string name = std::filesystem::path(in).stem().string();
    ThreadLimit limit(threads);
    std::printf(
        "| volume | mesher | output | threads | median ms of %d | min ms | triangles | vertices | "
        "ns per cell per thread | M triangles/s |\n|---|---|---|---|---|---|---|---|---|---|\n",
        runs);
    std::stringstream list(algorithms);
    for (std::string a; std::getline(list, a, ',');) {
      MeshOptions options;
      options.algorithm = parse_mesher(a);
      Mesh mesh;
      const bench::Timing fresh = bench::time_runs(runs, [&] {
        mesh = Mesh{};  // the previous mesh's pages go back before the next is made
        mesh = mesh_volume(volume, options);
      });
      const MeshCounts counts{mesh.vertex_count(), mesh.indices.size()};
      // Reused arrays sized by the first mesh (mesh_bound's worst case would do as well, at more
      // address space); the warm-up call touches their pages, the timed calls reuse them.
      MeshBuffers out{mesh.positions, mesh.normals, {}, mesh.indices};
      MeshCounts written;
      const bench::Timing reused =
          bench::time_runs(runs, [&] { written = mesh_volume_into(volume, options, out); });
      if (written.vertices != counts.vertices || written.indices != counts.indices) {
        std::fprintf(stderr, "voxfield-bench-mesh: %s: the reused path wrote another mesh\n",
                     a.c_str());
        return 1;
      }
      print_row(name, mesher_name(options.algorithm), "fresh (mesh_volume)", threads, fresh, counts,
                cells);
      print_row(name, mesher_name(options.algorithm), "reused (mesh_volume_into)", threads, reused,
                counts, cells);
      std::fflush(stdout);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "voxfield-bench-mesh: %s\n", e.what());
    return 1;
  }
  return 0;
}
