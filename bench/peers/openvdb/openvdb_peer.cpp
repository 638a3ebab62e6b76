// OpenVDB peer for voxfield's field benchmark: the same .npy inputs through
// openvdb::tools::topologyToLevelSet (narrow band, half-width 3) and openvdb::tools::fogToSdf
// (full signed distance), on 2 threads, median of N runs after a warm-up.
//
// OpenVDB measures distance to the interface between solid and air voxel centres (the 0.5
// isosurface of the occupancy), voxfield between voxel centres; so the error reported here is
// that of fogToSdf's air values against voxfield's exact Euclidean distance minus 0.5.
#include <openvdb/openvdb.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/TopologyToLevelSet.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "bench_util.h"
#include "voxfield/distance.h"
#include "voxfield/npy.h"

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: openvdb_peer RUNS OUT.jsonl input.npy...\n");
    return 2;
  }
  const int runs = std::atoi(argv[1]);
  std::ofstream json(argv[2], std::ios::app);
  openvdb::initialize();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 2);
  for (int a = 3; a < argc; ++a) {
    const voxfield::NpyVolume v = voxfield::read_npy(argv[a]);
    const std::string name = std::filesystem::path(argv[a]).stem().string();
    openvdb::FloatGrid::Ptr fog = openvdb::FloatGrid::create(0.0f);
    openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create();
    {
      auto fa = fog->getAccessor();
      auto ma = mask->getAccessor();
      for (int z = 0; z < v.dims.z; ++z)
        for (int y = 0; y < v.dims.y; ++y)
          for (int x = 0; x < v.dims.x; ++x) {
            // fogToSdf keeps the fog's topology: every voxel of the volume is active.
            const bool solid = v.value(x + static_cast<std::int64_t>(v.dims.x) *
                                               (y + static_cast<std::int64_t>(v.dims.y) * z)) != 0;
            fa.setValue({x, y, z}, solid ? 1.0f : 0.0f);
            if (solid) ma.setValueOn({x, y, z});
          }
    }
    const double voxels = static_cast<double>(v.count());
    auto record = [&](const char* what, voxfield::bench::Timing t, double max_err) {
      std::printf("%-26s %-22s %4d %9.1f %9.1f %9.1f %10.1f  max err %.2f\n", name.c_str(), what, 2,
                  t.median_ms, t.min_ms, t.max_ms, voxels / (t.median_ms * 1e3), max_err);
      std::fflush(stdout);
      json << "{\"tool\": \"openvdb\", \"input\": \"" << name << "\", \"metric\": \"" << what
           << "\", \"threads\": 2, \"voxels\": " << voxels << ", \"median_ms\": " << t.median_ms
           << ", \"min_ms\": " << t.min_ms << ", \"max_ms\": " << t.max_ms << ", \"runs\": " << runs
           << ", \"max_error\": " << max_err << "}\n";
    };
    openvdb::FloatGrid::Ptr band;
    const auto t_band = voxfield::bench::time_runs(
        runs, [&] { band = openvdb::tools::topologyToLevelSet(*mask, 3); });
    record("topologyToLevelSet-hw3", t_band, -1);
    openvdb::FloatGrid::Ptr sdf;
    const auto t_sdf =
        voxfield::bench::time_runs(runs, [&] { sdf = openvdb::tools::fogToSdf(*fog, 0.5f); });
    // Error of the full SDF in air, against voxfield's exact Euclidean distance minus 0.5.
    voxfield::World w(32, voxfield::Box3i::from_size(v.dims));
    w.voxels.copy_from_dense(voxfield::Box3i::from_size(v.dims), v.bytes.data());
    voxfield::DistanceOptions o;
    o.metric = voxfield::Metric::kEuclidean;
    const voxfield::DistanceField exact = voxfield::compute_distance_field(w, o);
    double max_err = 0;
    auto acc = sdf->getConstAccessor();
    for (int z = 0; z < v.dims.z; ++z)
      for (int y = 0; y < v.dims.y; ++y)
        for (int x = 0; x < v.dims.x; ++x) {
          const double e = exact.distance({x, y, z});
          if (e <= 0 || std::isinf(e)) continue;
          max_err = std::max(
              max_err,
              std::abs(std::abs(static_cast<double>(acc.getValue({x, y, z}))) - (e - 0.5)));
        }
    record("fogToSdf", t_sdf, max_err);
  }
}
