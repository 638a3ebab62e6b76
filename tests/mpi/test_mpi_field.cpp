// The MPI layer (mpi.h) against one process: run under mpirun with 1..N ranks, every rank builds
// the same random world, keeps its slab, and the distributed field's slab must equal the
// single-process field over the whole domain bit for bit (values and nearest sites), for every
// metric, sign, clamp, storage and spacing; failures on one rank must reach every rank as the same
// RankError (no hang), and a failed write must leave the target as it was.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "mpi_ranks.h"
#include "voxfield/distance_executor.h"
#include "voxfield/distance_slab.h"
#include "voxfield/dynamic_field.h"
#include "voxfield/file.h"
#include "voxfield/limits.h"
#include "voxfield/mpi.h"
#include "voxfield/npy.h"

namespace voxfield {
namespace {

using test::comm;
using test::rank;
using test::ranks;

template <class T>
std::vector<T> dense(const Grid<T>& g, const Box3i& box) {
  std::vector<T> v(static_cast<std::size_t>(box.volume()));
  g.copy_to_dense(box, v.data());
  return v;
}

World random_world(std::uint32_t seed, Box3i& domain, int edge, double density = -1) {
  std::mt19937 rng(seed);
  const Vec3i origin{static_cast<int>(rng() % 30) - 15, static_cast<int>(rng() % 30) - 15,
                     static_cast<int>(rng() % 30) - 15};
  const Vec3i size{4 + static_cast<int>(rng() % 20), 3 + static_cast<int>(rng() % 20),
                   ranks() + static_cast<int>(rng() % 60)};
  domain = {origin, origin + size};
  World w(edge, domain);
  if (density < 0) density = std::array<double, 3>{0.003, 0.15, 0.9}[seed % 3];
  std::bernoulli_distribution solid(density);
  for (int z = domain.begin.z; z < domain.end.z; ++z)
    for (int y = domain.begin.y; y < domain.end.y; ++y)
      for (int x = domain.begin.x; x < domain.end.x; ++x)
        if (solid(rng)) w.voxels.set({x, y, z}, 1);
  return w;
}

// Every rank computes the whole field too: the oracle. With a device executor, each rank computes
// its slab on it (the Executor overload); otherwise on the CPU from its occupancy alone.
void check(const DistanceOptions& base, std::uint32_t seed, int align,
           const Executor& executor = {}) {
  Box3i domain;
  const int edge = seed % 2 ? 8 : 16;
  const World w = random_world(seed, domain, edge);
  const mpi::SlabPartition p = mpi::partition_slabs(domain, ranks(), align);
  const Box3i slab = p.slab(rank());
  World mine(edge, slab);  // this rank's voxels only
  mine.voxels.copy_from_dense(slab, dense(w.voxels, slab).data());
  mpi::ExchangeStats stats;
  const DistanceField f = executor.on_gpu()
                              ? mpi::compute_distance_field(comm(), p, mine, base, executor, &stats)
                              : mpi::compute_distance_field(comm(), p, mine.voxels, base, &stats);
  DistanceOptions whole_o = base;
  whole_o.domain = domain;
  const DistanceField whole = compute_distance_field(w.voxels, whole_o);
  const std::string what = std::string(metric_name(base.metric)) +
                           (base.signed_distance ? " signed" : "") + " clamp " +
                           std::to_string(base.max_distance) + " " + storage_name(base.storage) +
                           (base.nearest_sites ? " sites" : "") + " seed " + std::to_string(seed) +
                           " rank " + std::to_string(rank());
  ASSERT_EQ(f.domain, slab) << what;
  std::visit(
      [&](const auto& g) {
        using G = std::decay_t<decltype(g)>;
        EXPECT_EQ(dense(g, slab), dense(std::get<G>(whole.values), slab)) << what;
      },
      f.values);
  if (base.nearest_sites) {
    ASSERT_TRUE(f.sites) << what;
    EXPECT_EQ(dense(*f.sites, slab), dense(*whole.sites, slab)) << what;
  }
  // 8 bytes per column go up the chain of ranks (the highest solid and air voxel) and 8 down
  // (the lowest), nothing more: the top rank sends nothing up, the bottom one nothing down.
  const std::uint64_t columns = static_cast<std::uint64_t>(domain.size().x) * domain.size().y;
  const std::uint64_t hops = (rank() + 1 < ranks() ? 1 : 0) + (rank() > 0 ? 1 : 0);
  EXPECT_EQ(stats.bytes_sent, 8 * columns * hops) << what;
  EXPECT_EQ(stats.bytes_received, 8 * columns * hops) << what;
}

TEST(MpiField, EqualsOneProcessForEveryOption) {
  std::uint32_t seed = 1;
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool sgn : {false, true})
      for (double clamp : {0.0, 4.5})
        for (Storage st : {Storage::kF32, Storage::kU8, Storage::kU16})
          for (bool sites : {false, true}) {
            DistanceOptions o;
            o.metric = m;
            o.signed_distance = sgn;
            o.max_distance = clamp;
            o.storage = st;
            o.nearest_sites = sites;
            check(o, seed, seed % 3 == 0 ? 1 : 8);
            ++seed;
          }
  for (bool sgn : {false, true}) {
    DistanceOptions o;
    o.metric = Metric::kEuclidean;
    o.signed_distance = sgn;
    o.spacing = {0.5, 1.25, 2.0};
    o.nearest_sites = true;
    check(o, seed++, 1);
  }
}

// Edits applied by every rank to its slab and ghost slices, against one process's incremental
// field after the same edits (itself tested against full rebuilds), checked every few edits.
void check_edits(const DistanceOptions& o, std::uint32_t seed, const Executor& executor = {}) {
  Box3i domain;
  const int edge = seed % 2 ? 8 : 16;
  // Sparse worlds: a voxel's nearest site is often far along z, where a missing ghost slice shows.
  World whole = random_world(seed, domain, edge, seed % 2 ? 0.002 : 0.02);
  const mpi::SlabPartition p = mpi::partition_slabs(domain, ranks(), seed % 3 ? 8 : 1);
  const int ghost = mpi::edit_ghost_slices(o);
  const bool unclamped = !std::isfinite(effective_clamp(o));
  EXPECT_EQ(ghost == 0, unclamped);
  const Box3i slab = p.slab(rank());
  const Box3i box{{domain.begin.x, domain.begin.y, std::max(domain.begin.z, slab.begin.z - ghost)},
                  {domain.end.x, domain.end.y, std::min(domain.end.z, slab.end.z + ghost)}};
  World mine(edge, box);  // this rank's box only
  mine.voxels.copy_from_dense(box, dense(whole.voxels, box).data());
  mpi::SlabEditor editor(comm(), p, mine, o, executor);
  // An unclamped field is computed by the first refresh(), after the edits before it.
  EXPECT_EQ(editor.stale(), unclamped);
  if (unclamped) {
    EXPECT_THROW((void)editor.field(), InvalidArgument);
  }
  DynamicDistanceField oracle(whole, o);
  DirtyRegions dirty(edge, DirtyRegions::Track::kOccupancy);
  std::mt19937 rng(seed * 7 + 1);
  const Vec3i s = domain.size();
  for (int i = 0; i < 40; ++i) {
    Edit e;
    e.op = i % 3 == 0 ? EditOp::kCarve : (i % 3 == 1 ? EditOp::kPlace : EditOp::kPaint);
    e.material = static_cast<std::uint8_t>(1 + rng() % 4);
    const Vec3i c = domain.begin + Vec3i{static_cast<int>(rng() % (s.x + 6)) - 3,
                                         static_cast<int>(rng() % (s.y + 6)) - 3,
                                         static_cast<int>(rng() % (s.z + 6)) - 3};
    if (i % 2) {
      e.brush = SphereBrush{
          {static_cast<double>(c.x), static_cast<double>(c.y), static_cast<double>(c.z)},
          static_cast<double>(1 + rng() % 6)};
    } else {
      e.brush = BoxBrush{c, c + Vec3i{static_cast<int>(rng() % 8), static_cast<int>(rng() % 8),
                                      static_cast<int>(rng() % 20)}};
    }
    (void)editor.apply(e);
    (void)apply_edit(whole, e, &dirty);
    (void)oracle.update(dirty);
    dirty.clear();
    if (i % 4 != 3) continue;
    // An unclamped f32 field follows the edits at refresh() (on every rank; a clamped one needs
    // none, and says so).
    int stale = editor.stale() ? 1 : 0, any_stale = 0;
    MPI_Allreduce(&stale, &any_stale, 1, MPI_INT, MPI_MAX, comm());
    EXPECT_TRUE(unclamped || any_stale == 0);  // a clamped field is never stale
    std::int64_t refreshed_voxels = -1;
    const bool refreshed = editor.refresh(comm(), nullptr, &refreshed_voxels);
    EXPECT_EQ(refreshed, any_stale != 0);
    EXPECT_EQ(refreshed_voxels, refreshed ? slab.volume() : 0);
    EXPECT_FALSE(editor.stale());
    if (unclamped) {
      EXPECT_EQ(editor.field().domain, slab);
    }
    const std::string what = std::string(metric_name(o.metric)) +
                             (o.signed_distance ? " signed" : "") + " clamp " +
                             std::to_string(o.max_distance) + " " + storage_name(o.storage) +
                             (o.nearest_sites ? " sites" : "") + " seed " + std::to_string(seed) +
                             " edit " + std::to_string(i) + " rank " + std::to_string(rank());
    std::visit(
        [&](const auto& g) {
          using G = std::decay_t<decltype(g)>;
          ASSERT_EQ(dense(g, slab), dense(std::get<G>(oracle.field().values), slab)) << what;
        },
        editor.field().values);
    if (o.nearest_sites) {
      ASSERT_EQ(dense(*editor.field().sites, slab), dense(*oracle.field().sites, slab)) << what;
    }
    EXPECT_EQ(dense(editor.world().voxels, slab), dense(whole.voxels, slab)) << what;
  }
}

// f(options) for every metric, signed or not, with nearest sites or not (the other options
// default).
template <class F>
void for_every_kind_of_field(F&& f) {
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool sgn : {false, true})
      for (bool sites : {false, true}) {
        DistanceOptions o;
        o.metric = m;
        o.signed_distance = sgn;
        o.nearest_sites = sites;
        f(o);
      }
}

TEST(MpiField, EditsKeepEverySlabEqualToOneProcess) {
  std::uint32_t seed = 500;
  for_every_kind_of_field([&](DistanceOptions o) {
    o.max_distance = 2.5 + static_cast<double>(seed % 6);
    check_edits(o, seed++);
    o.max_distance = 0;
    o.storage = Storage::kU8;  // the storage's range is the clamp
    check_edits(o, seed++);
  });
}

// Unclamped f32 fields: every rank keeps its slab alone, and refresh() computes the field over the
// ranks again after the edits; every few edits it must equal one process's incremental field.
TEST(MpiField, UnclampedEditsRefreshEverySlabToOneProcess) {
  std::uint32_t seed = 700;
  for_every_kind_of_field([&](const DistanceOptions& o) { check_edits(o, seed++); });
}

// The same with every rank on a Vulkan device of its own (lavapipe here): each slab from its
// device's transform, its z passes starting from the neighbours the ranks exchanged, and edits
// kept by each rank's device field (or, unclamped, computed again over the devices). Integer
// storage and f32 values without square roots are the CPU's bits (gpu_distance.h).
TEST(MpiField, EveryRankOnItsOwnDeviceEqualsOneProcess) {
  std::shared_ptr<gpu::Context> device;
  try {
    device = gpu::Context::create();
  } catch (const Error&) {  // no device, or a build without Vulkan
  }
  int mine = device ? 1 : 0, every = 0;
  MPI_Allreduce(&mine, &every, 1, MPI_INT, MPI_MIN, comm());
  if (every == 0) GTEST_SKIP() << "a rank has no Vulkan device";
  const Executor gpu(device);
  std::uint32_t seed = 900;
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool sgn : {false, true})
      for (Storage st : {Storage::kU8, Storage::kU16, Storage::kF32}) {
        if (st == Storage::kF32 && m == Metric::kEuclidean)
          continue;  // square roots: within
                     // kF32Tolerance, not bits
        DistanceOptions o;
        o.metric = m;
        o.signed_distance = sgn;
        o.storage = st;
        o.max_distance = seed % 2 ? 0.0 : 4.5;
        o.nearest_sites = seed % 3 == 0;
        check(o, seed, 8, gpu);
        ++seed;
      }
  EXPECT_GT(device->counters().submits, 0);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.max_distance = 3.5;
  o.storage = Storage::kU8;
  check_edits(o, 950, gpu);
  o.metric = Metric::kChebyshev;
  o.max_distance = 0;
  o.storage = Storage::kF32;
  o.nearest_sites = true;
  check_edits(o, 951, gpu);
}

TEST(MpiField, PartitionsCoverTheDomainInOrder) {
  for (int n : {1, 2, 3, 4, 7}) {
    for (const Box3i d : {Box3i{{0, 0, 0}, {5, 5, 7}}, Box3i{{0, 0, -37}, {3, 2, 100}},
                          Box3i{{1, 1, 5}, {2, 2, 300}}}) {
      for (int align : {1, 8, 32}) {
        const mpi::SlabPartition p = mpi::partition_slabs(d, n, align);
        ASSERT_EQ(p.ranks(), n);
        EXPECT_EQ(p.z.front(), d.begin.z);
        EXPECT_EQ(p.z.back(), d.end.z);
        std::int64_t total = 0;
        // Cuts on multiples of align whenever every rank can have a unit of it (what a .vfw
        // written by every rank needs).
        const std::int64_t base =
            (d.begin.z >= 0 ? d.begin.z / align : (d.begin.z - align + 1) / align) * align;
        const bool units_for_all = (d.end.z - base + align - 1) / align >= n;
        for (int r = 0; r < n; ++r) {
          EXPECT_LT(p.z[r], p.z[r + 1]) << "every rank owns a slice";
          if (r > 0 && units_for_all) {
            EXPECT_EQ(p.z[r] % align, 0) << "cut " << r << " of " << n;
          }
          total += p.slab(r).volume();
        }
        EXPECT_EQ(total, d.volume());
      }
    }
  }
  EXPECT_THROW(mpi::partition_slabs(Box3i{{0, 0, 0}, {4, 4, 3}}, 4, 1), InvalidArgument);
  EXPECT_THROW(mpi::partition_slabs(Box3i{}, 1, 1), InvalidArgument);
}

// Weighted slabs: units tile the domain; each cut lies on a unit boundary where the running weight
// is nearest its share, every rank keeping at least one unit; bad weights refused. The edits' and
// the content's weights fall where the edits and the surface are.
TEST(MpiField, SlabsWeighedByWorkCutWhereTheWorkIs) {
  const Box3i d{{0, 0, -5}, {16, 16, 75}};  // units of 16: [-5,0) [0,16) ... [64,75): 6
  const std::vector<Box3i> units = mpi::slab_units(d, 16);
  ASSERT_EQ(units.size(), 6u);
  EXPECT_EQ(units.front().begin.z, -5);
  EXPECT_EQ(units.front().end.z, 0);
  EXPECT_EQ(units.back().begin.z, 64);
  EXPECT_EQ(units.back().end.z, 75);
  const std::vector<double> w{0, 0, 0, 10, 10, 0};  // the work in [32, 64)
  EXPECT_EQ(mpi::partition_slabs(d, 2, 16, w).z, (std::vector<std::int32_t>{-5, 48, 75}));
  // Four ranks over two units of work: each rank still gets a unit.
  EXPECT_EQ(mpi::partition_slabs(d, 4, 16, w).z, (std::vector<std::int32_t>{-5, 32, 48, 64, 75}));
  EXPECT_EQ(mpi::partition_slabs(d, 6, 16, w).z,
            (std::vector<std::int32_t>{-5, 0, 16, 32, 48, 64, 75}));
  // No weight at all, or more ranks than units: the slabs of equal volume.
  EXPECT_EQ(mpi::partition_slabs(d, 3, 16, std::vector<double>(6, 0.0)).z,
            mpi::partition_slabs(d, 3, 16).z);
  EXPECT_EQ(mpi::partition_slabs(d, 7, 16, w).z, mpi::partition_slabs(d, 7, 16).z);
  EXPECT_THROW(mpi::partition_slabs(d, 2, 16, std::vector<double>(5, 1.0)), InvalidArgument);
  EXPECT_THROW(mpi::partition_slabs(d, 2, 16, {0, 0, -1, 0, 0, 0}), InvalidArgument);
  EXPECT_THROW(mpi::partition_slabs(d, 2, 16, {0, 0, std::nan(""), 0, 0, 0}), InvalidArgument);
  // A sphere of radius 2 at z 40, its reach grown by 3 slices: z in [35, 46), all within unit 3.
  Edit e;
  e.brush = SphereBrush{{5, 5, 40}, 2};
  const std::vector<double> ew = mpi::edit_unit_weights(d, 16, {e, e}, 3);
  ASSERT_EQ(ew.size(), 6u);
  const Box3i reach = brush_bounds(e.brush).grown(3).intersect(d);
  EXPECT_EQ(ew[3], 2.0 * static_cast<double>(reach.volume()));
  EXPECT_EQ(ew[0] + ew[1] + ew[2] + ew[4] + ew[5], 0.0);
  // Content: a flat ground at z 40 in a world chunked by 16 — its surface chunk is in unit 3; the
  // solid chunks below are uniform, and air holds none.
  World ground;
  ground.voxels = Grid<std::uint8_t>(16);
  ground.voxels.fill(Box3i{{0, 0, -16}, {16, 16, 40}}, 1);
  const mpi::SlabPartition p = mpi::partition_slabs(d, ranks(), 16);
  const std::vector<double> cw = mpi::content_unit_weights(comm(), p, ground, 16);
  ASSERT_EQ(cw.size(), 6u);
  for (std::size_t k = 0; k < cw.size(); ++k) {
    EXPECT_EQ(cw[k], (k == 3 ? 1.0 : 0.0) + 1.0 / 64) << "unit " << k;
  }
  // A domain within one unit, off the chunk grid (every rank a slice of it): its one unit holds
  // the surface, counted once over the ranks; the voxels past the domain are no one's.
  const Box3i thin{{0, 0, 37}, {16, 16, 37 + std::max(ranks(), 4)}};  // the ground at 40 within
  const std::vector<double> tw =
      mpi::content_unit_weights(comm(), mpi::partition_slabs(thin, ranks(), 16), ground, 16);
  ASSERT_EQ(tw.size(), 1u);
  EXPECT_EQ(tw[0], 1.0 + 1.0 / 64);
}

TEST(MpiField, AFailureOnOneRankReachesEveryRank) {
  if (ranks() < 2) GTEST_SKIP() << "needs two ranks";
  Box3i domain;
  const World w = random_world(7, domain, 8);
  const mpi::SlabPartition p = mpi::partition_slabs(domain, ranks(), 1);
  // The last rank alone may hold almost nothing: its slab's field passes its limit.
  const bool last = rank() == ranks() - 1;
  if (last) set_default_memory_limit(64);
  try {
    (void)mpi::compute_distance_field(comm(), p, w.voxels, DistanceOptions{});
    ADD_FAILURE() << "no rank failed";
  } catch (const mpi::RankError& e) {
    EXPECT_EQ(e.rank(), ranks() - 1) << e.what();
    EXPECT_NE(e.message().find("memory"), std::string::npos) << e.what();
  }
  set_default_memory_limit(0);
  // A partition for another number of ranks is refused by every rank alike.
  const mpi::SlabPartition wrong = mpi::partition_slabs(domain, ranks() + 1, 1);
  EXPECT_THROW((void)mpi::compute_distance_field(comm(), wrong, w.voxels, DistanceOptions{}),
               mpi::RankError);
}

TEST(MpiField, WritesOneFileOrNothing) {
  Box3i domain;
  const World w = random_world(11, domain, 8);
  const mpi::SlabPartition p = mpi::partition_slabs(domain, ranks(), 8);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.signed_distance = true;
  o.nearest_sites = true;
  const DistanceField f = mpi::compute_distance_field(comm(), p, w.voxels, o);
  // The same directory on every rank: rank 0 makes it.
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("voxfield_mpi_test_" + std::to_string(ranks()));
  if (rank() == 0) {
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
  }
  MPI_Barrier(comm());
  mpi::FieldFiles files{dir / "f.npy", dir / "s.npy", dir / "f.json", "{}\n", {}, nullptr, {}};
  mpi::write_field_npy(comm(), p, f, files);
  if (rank() == 0) {
    DistanceOptions whole_o = o;
    whole_o.domain = domain;
    const DistanceField whole = compute_distance_field(w.voxels, whole_o);
    const NpyVolume back = read_npy(dir / "f.npy");
    EXPECT_EQ(back.dims, domain.size());
    std::vector<float> expect = dense(std::get<Grid<float>>(whole.values), domain);
    std::vector<float> got(expect.size());
    std::memcpy(got.data(), back.bytes.data(), got.size() * sizeof(float));
    EXPECT_EQ(got, expect);
    EXPECT_EQ(read_file(dir / "f.json").size(), 3u);
    // The sites: int16 a[x, y, z, 3], the three offsets as planes.
    const std::vector<std::uint8_t> sites_file = read_file(dir / "s.npy");
    const std::vector<SiteOffset> expect_sites = dense(*whole.sites, domain);
    const std::size_t n = expect_sites.size();
    ASSERT_GE(sites_file.size(), 6 * n);
    const std::uint8_t* planes = sites_file.data() + (sites_file.size() - 6 * n);
    for (std::size_t i = 0; i < n; i += 7) {
      std::int16_t d[3];
      for (int c = 0; c < 3; ++c) std::memcpy(&d[c], planes + 2 * (c * n + i), 2);
      ASSERT_EQ((SiteOffset{d[0], d[1], d[2]}), expect_sites[i]) << "voxel " << i;
    }
  }
  // A read-only target: refused by rank 0 before anything is written, on every rank alike, and
  // neither it nor the other outputs change.
  if (rank() == 0) {
    std::ofstream(dir / "ro.npy") << "keep";
    std::filesystem::permissions(dir / "ro.npy", std::filesystem::perms::owner_read);
  }
  MPI_Barrier(comm());
  const auto before = rank() == 0 ? read_file(dir / "f.npy") : std::vector<std::uint8_t>{};
  mpi::FieldFiles bad{dir / "f.npy", dir / "ro.npy", {}, {}, {}, nullptr, {}};
  EXPECT_THROW(mpi::write_field_npy(comm(), p, f, bad), mpi::RankError);
  if (rank() == 0) {
    EXPECT_EQ(read_file(dir / "f.npy"), before);
    EXPECT_EQ(read_file(dir / "ro.npy").size(), 4u);
    std::size_t entries = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir)) {
      (void)e;
      ++entries;
    }
    EXPECT_EQ(entries, 4u) << "a temporary was left behind";
    std::filesystem::permissions(dir / "ro.npy", std::filesystem::perms::owner_all);
    std::filesystem::remove_all(dir);
  }
}

}  // namespace
}  // namespace voxfield

// gtest under MPI: every rank runs every test and prints (failures name their rank); the exit
// status is the worst rank's.
int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  ::testing::InitGoogleTest(&argc, argv);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const int mine = RUN_ALL_TESTS();
  int worst = 0;
  MPI_Allreduce(&mine, &worst, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  MPI_Finalize();
  return worst;
}
