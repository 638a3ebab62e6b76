// An application of the installed voxfield package: builds a world, computes its exact Euclidean
// field and checks it against the analytic answer, saves and reloads it through the io layer.
// Exit status 0 when every check holds.
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "voxfield/distance.h"
#include "voxfield/gpu.h"
#include "voxfield/world_io.h"
#ifdef CONSUMER_VULKAN
#include "voxfield/gpu_vulkan.h"  // needs the Vulkan headers: the vulkan component provides them
#endif
#ifdef CONSUMER_MPI
#include <mpi.h>

#include "voxfield/mpi.h"  // the mpi component: voxfield::mpi and MPI::MPI_CXX
#endif

int main(int argc, char** argv) {
  using namespace voxfield;
  const Box3i domain = Box3i::from_size({32, 32, 32});
  World world(32, domain);
  world.voxels.set({10, 20, 5}, 7);  // one solid voxel: the distance at p is |p - (10, 20, 5)|
  DistanceOptions options;
  options.metric = Metric::kEuclidean;
  const DistanceField field = compute_distance_field(world, options);
  int wrong = 0;
  for (const Vec3i p : {Vec3i{0, 0, 0}, Vec3i{31, 31, 31}, Vec3i{13, 24, 5}, Vec3i{10, 20, 6}}) {
    const double dx = p.x - 10, dy = p.y - 20, dz = p.z - 5;
    const double expected = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (std::abs(field.distance(p) - expected) > 1e-5) {
      std::fprintf(stderr, "distance at (%d, %d, %d): %g, expected %g\n", p.x, p.y, p.z,
                   field.distance(p), expected);
      ++wrong;
    }
  }
#ifdef CONSUMER_MPI
  // The same field through the MPI layer, over the ranks of this job (one when run on its own):
  // each rank's slab equals the single-process field there.
  int provided = 0;  // only this thread talks to MPI; voxfield's pool works between the calls
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  if (provided < MPI_THREAD_FUNNELED) {
    std::fprintf(stderr, "MPI gives thread level %d, below MPI_THREAD_FUNNELED\n", provided);
    ++wrong;
  }
  int ranks = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const mpi::SlabPartition partition = mpi::partition_slabs(domain, ranks);
  const Box3i slab = partition.slab(rank);
  const DistanceField part =
      mpi::compute_distance_field(MPI_COMM_WORLD, partition, world.voxels, options);
  std::int64_t differ = 0;
  for (int z = slab.begin.z; z < slab.end.z; ++z)
    for (int y = slab.begin.y; y < slab.end.y; ++y)
      for (int x = slab.begin.x; x < slab.end.x; ++x)
        differ += part.distance({x, y, z}) != field.distance({x, y, z});
  if (differ) {
    std::fprintf(stderr, "rank %d: %lld voxels of the MPI layer's field differ\n", rank,
                 static_cast<long long>(differ));
    ++wrong;
  }
  MPI_Finalize();
  std::printf("voxfield consumer: MPI layer on %d rank(s) %s\n", ranks, differ ? "FAILED" : "ok");
#endif
  const std::filesystem::path path =
      std::filesystem::path(argc > 1 ? argv[1] : ".") / "consumer.npy";
  save_world(world, domain, path);
  const LoadedWorld back = load_world(path);
  if (back.world.solid_count() != 1 || back.world.voxels.get({10, 20, 5}) == 0) {
    std::fprintf(stderr, "%s: the saved world did not come back\n", path.c_str());
    ++wrong;
  }
  std::printf("voxfield consumer: %s, Vulkan backend %s\n", wrong ? "FAILED" : "ok",
              gpu::built_with_vulkan() ? "built" : "not built");
  return wrong ? 1 : 0;
}
