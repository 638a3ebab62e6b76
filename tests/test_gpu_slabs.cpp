// Slabs of exact fields on the GPU (gpu::compute_slab_distance_field): a domain cut into z-slabs,
// each computed on the device from a world holding only its own voxels and the nearest sites
// beyond it (what voxfield-mpi exchanges), must equal the CPU's slab (distance_slab.h) — integer
// storage bit for bit, f32 within gpu::kF32Tolerance, every voxel's nearest site — for every
// metric, sign, clamp and storage, also when a small device cuts a slab into parts. Bad neighbours
// are refused as on the CPU, before anything is uploaded.
#include <gtest/gtest.h>

#include <random>
#include <utility>

#include "gpu_fields.h"
#include "gpu_suite.h"
#include "slab_neighbours.h"
#include "voxfield/distance_slab.h"
#include "voxfield/error.h"
#include "voxfield/gpu_distance.h"

using namespace voxfield;
using test::expect_same_field;
using test::gpu_tests_wanted;
using test::neighbours_of;

namespace {

// A world over `domain` with solids of density `density`, and its slabs at `cuts` (z), each a
// world of its own voxels alone with the column sites of its own voxels.
struct SlabbedWorld {
  Box3i domain;
  std::vector<int> cuts;
  std::vector<World> slabs;
  std::vector<ColumnSites> extremes;

  Box3i slab(std::size_t i) const {
    return {{domain.begin.x, domain.begin.y, cuts[i]}, {domain.end.x, domain.end.y, cuts[i + 1]}};
  }
};

SlabbedWorld slabbed_world(const Box3i& domain, std::vector<int> cuts, double density,
                           std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution solid(density);
  World w(8, domain);
  for (int z = domain.begin.z; z < domain.end.z; ++z)
    for (int y = domain.begin.y; y < domain.end.y; ++y)
      for (int x = domain.begin.x; x < domain.end.x; ++x)
        if (solid(rng)) w.voxels.set({x, y, z}, static_cast<std::uint8_t>(1 + rng() % 3));
  SlabbedWorld out{domain, std::move(cuts), {}, {}};
  for (std::size_t i = 0; i + 1 < out.cuts.size(); ++i) {
    const Box3i box = out.slab(i);
    World part(8, box);
    std::vector<std::uint8_t> voxels(static_cast<std::size_t>(box.volume()));
    w.voxels.copy_to_dense(box, voxels.data());
    part.voxels.copy_from_dense(box, voxels.data());
    out.extremes.push_back(slab_column_sites(part.voxels, domain, box.begin.z, box.end.z));
    out.slabs.push_back(std::move(part));
  }
  return out;
}

}  // namespace

TEST(GpuSlabs, EachSlabEqualsTheCpusSlab) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  const std::shared_ptr<gpu::Context> ctx = test::validated_context();
  // Sparse solids: many columns of a thin slab hold none of their own, so their values come from
  // the neighbours alone (a z pass that ignored them would find no site at all).
  const Box3i domain{{-5, 3, -11}, {24, 22, 30}};
  const SlabbedWorld w = slabbed_world(domain, {-11, -4, -3, 13, 30}, 0.015, 7);
  std::size_t slabs_checked = 0;
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool is_signed : {false, true})
      for (double clamp : {0.0, 4.5})
        for (Storage storage : {Storage::kU8, Storage::kF32})
          for (bool sites : {false, true}) {
            DistanceOptions o;
            o.metric = m;
            o.signed_distance = is_signed;
            o.max_distance = clamp;
            o.storage = storage;
            o.nearest_sites = sites;
            o.domain = domain;
            for (std::size_t i = 0; i < w.slabs.size(); ++i) {
              const Box3i box = w.slab(i);
              const SlabNeighbours n = neighbours_of(w.extremes, i);
              const std::string what = std::string(metric_name(m)) + (is_signed ? " signed" : "") +
                                       " clamp " + std::to_string(clamp) + " " +
                                       storage_name(storage) + (sites ? " sites" : "") + " slab " +
                                       to_string(box);
              const DistanceField gpu_slab =
                  gpu::compute_slab_distance_field(*ctx, w.slabs[i], o, box.begin.z, box.end.z, n);
              const DistanceField cpu_slab =
                  compute_slab_distance_field(w.slabs[i].voxels, o, box.begin.z, box.end.z, n);
              ASSERT_EQ(gpu_slab.domain, box) << what;
              expect_same_field(gpu_slab, cpu_slab, what);
              ++slabs_checked;
            }
          }
  EXPECT_EQ(slabs_checked, 3u * 2 * 2 * 2 * 2 * 4);
  test::expect_no_validation_messages(*ctx);
}

TEST(GpuSlabs, ASlabCutIntoPartsOrThinnerSlabsByASmallDeviceStillEqualsTheCpusSlab) {
  // A clamped slab too large for one work buffer is computed in parts, each with the sites
  // within its reach: the parts whose box reaches a face of the slab start their columns from the
  // neighbours beyond it (the others lie farther than the clamp from those). The 32 x 24 slab is
  // cut across x (every part reaches both faces); the tall 16 x 16 one across z, into a part that
  // reaches only the lower face and one that reaches only the upper, whose box starts above the
  // slab's first slice (the neighbours' offsets count from that slice).
  if (!gpu_tests_wanted()) GTEST_SKIP();
  const test::CappedAndWhole contexts = test::capped_and_whole(64 * 1024);
  const Box3i domain{{0, 0, 0}, {32, 24, 60}};
  const SlabbedWorld w = slabbed_world(domain, {0, 11, 45, 60}, 0.01, 11);
  const SlabbedWorld tall = slabbed_world({{0, 0, 0}, {16, 16, 110}}, {0, 11, 91, 110}, 0.004, 12);
  for (const SlabbedWorld* world : {&w, &tall})
    for (Metric m : {Metric::kManhattan, Metric::kEuclidean})
      for (bool is_signed : {false, true}) {
        DistanceOptions o;
        o.metric = m;
        o.signed_distance = is_signed;
        o.max_distance = 5;
        o.storage = Storage::kU16;
        o.domain = world->domain;
        const std::size_t i = 1;  // 104 448 and 81 920 bytes per cost buffer
        const Box3i box = world->slab(i);
        const SlabNeighbours n = neighbours_of(world->extremes, i);
        const std::string what =
            std::string(metric_name(m)) + (is_signed ? " signed " : " ") + to_string(world->domain);
        const std::int64_t before = contexts.small->counters().dispatches;
        const DistanceField parts = gpu::compute_slab_distance_field(
            *contexts.small, world->slabs[i], o, box.begin.z, box.end.z, n);
        const std::int64_t in_parts = contexts.small->counters().dispatches - before;
        const std::int64_t before_whole = contexts.whole->counters().dispatches;
        const DistanceField one = gpu::compute_slab_distance_field(*contexts.whole, world->slabs[i],
                                                                   o, box.begin.z, box.end.z, n);
        EXPECT_GT(in_parts, contexts.whole->counters().dispatches - before_whole) << what;
        expect_same_field(parts, one, what);
        expect_same_field(
            parts,
            compute_slab_distance_field(world->slabs[i].voxels, o, box.begin.z, box.end.z, n),
            what);
      }
  // Unclamped, no cut with halos fits: the slab is cut into thinner z-slabs whose column
  // neighbours (edt_columns) start from the slab's own beyond its faces — both tables at once.
  for (const auto& [i, sites] : {std::pair<std::size_t, bool>{1, false}, {0, true}})
    for (Metric m : {Metric::kChebyshev, Metric::kEuclidean}) {
      DistanceOptions o;
      o.metric = m;
      o.signed_distance = true;
      o.storage = Storage::kF32;
      o.nearest_sites = sites;
      o.domain = domain;
      const Box3i box = w.slab(i);
      const SlabNeighbours n = neighbours_of(w.extremes, i);
      const std::string what = std::string(metric_name(m)) + " unclamped" + (sites ? " sites" : "");
      const DistanceField slabs = gpu::compute_slab_distance_field(*contexts.small, w.slabs[i], o,
                                                                   box.begin.z, box.end.z, n);
      expect_same_field(
          slabs, compute_slab_distance_field(w.slabs[i].voxels, o, box.begin.z, box.end.z, n),
          what);
    }
  test::expect_no_validation_messages(*contexts.small);
}

TEST(GpuSlabs, BadNeighboursAndSlicesTooLargeAreRefused) {
  if (!gpu_tests_wanted()) GTEST_SKIP();
  const std::shared_ptr<gpu::Context> ctx = test::validated_context();
  const Box3i domain{{0, 0, 0}, {12, 10, 20}};
  const SlabbedWorld w = slabbed_world(domain, {0, 8, 20}, 0.05, 3);
  DistanceOptions o;
  o.domain = domain;
  const SlabNeighbours good = neighbours_of(w.extremes, 0);
  // The same refusal on both backends, word for word.
  auto same_refusal = [&](const DistanceOptions& opts, std::int32_t z0, std::int32_t z1,
                          const SlabNeighbours& n, const std::string& expected) {
    std::string cpu, gpu_text;
    try {
      (void)compute_slab_distance_field(w.slabs[0].voxels, opts, z0, z1, n);
    } catch (const InvalidArgument& e) {
      cpu = e.what();
    }
    try {
      (void)gpu::compute_slab_distance_field(*ctx, w.slabs[0], opts, z0, z1, n);
    } catch (const InvalidArgument& e) {
      gpu_text = e.what();
    }
    EXPECT_NE(cpu.find(expected), std::string::npos) << cpu;
    EXPECT_EQ(gpu_text, cpu);
  };
  SlabNeighbours short_arrays = good;
  short_arrays.air_above.pop_back();
  same_refusal(o, 0, 8, short_arrays, "119 columns given, the domain has 120");
  SlabNeighbours inside = good;
  inside.solid_above[5] = 3;  // inside the slab: not above it
  same_refusal(o, 0, 8, inside, "a solid voxel at z 3 is not above the slab z 0..8");
  DistanceOptions no_domain = o;
  no_domain.domain.reset();
  same_refusal(no_domain, 0, 8, good, "needs the whole field's domain");

  // A slab of which not even one z-slice fits the work buffers' binding is refused by name
  // (40 x 30 voxels: 4800 bytes a cost buffer).
  const std::shared_ptr<gpu::Context> small = test::capped_context(4096);
  const Box3i wide{{0, 0, 0}, {40, 30, 6}};
  const SlabbedWorld v = slabbed_world(wide, {0, 3, 6}, 0.05, 4);
  DistanceOptions u;
  u.domain = wide;
  try {
    (void)gpu::compute_slab_distance_field(*small, v.slabs[1], u, 3, 6,
                                           neighbours_of(v.extremes, 1));
    ADD_FAILURE() << "a slab whose slices pass the work buffers' binding was computed";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("and so does one z-slice of it (40 x 30 voxels)"),
              std::string::npos)
        << e.what();
  }
}
