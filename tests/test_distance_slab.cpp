// Slabs of exact fields (distance_slab.h) against the whole field: a domain cut into z-slabs at
// random places, each slab computed from a grid holding only its own voxels plus the reductions
// of the other slabs' column sites (what voxfield-mpi exchanges), must equal the whole-domain
// field over the slab bit for bit — values and nearest sites — for every metric, sign, clamp,
// storage and spacing.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "slab_neighbours.h"
#include "voxfield/distance_slab.h"
#include "voxfield/error.h"

namespace voxfield {
namespace {

using test::neighbours_of;

struct Case {
  Metric metric;
  bool is_signed;
  double clamp;
  Storage storage;
  bool sites;
  std::array<double, 3> spacing{1, 1, 1};
};

template <class T>
std::vector<T> dense(const Grid<T>& g, const Box3i& box) {
  std::vector<T> v(static_cast<std::size_t>(box.volume()));
  g.copy_to_dense(box, v.data());
  return v;
}

void check_slabs(const Case& k, std::uint32_t seed, double density, int edge) {
  std::mt19937 rng(seed);
  const Vec3i origin{static_cast<int>(rng() % 40) - 20, static_cast<int>(rng() % 40) - 20,
                     static_cast<int>(rng() % 40) - 20};
  const Vec3i size{5 + static_cast<int>(rng() % 30), 3 + static_cast<int>(rng() % 25),
                   6 + static_cast<int>(rng() % 50)};
  const Box3i domain{origin, origin + size};
  World w(edge, domain);
  std::bernoulli_distribution solid(density);
  for (int z = domain.begin.z; z < domain.end.z; ++z)
    for (int y = domain.begin.y; y < domain.end.y; ++y)
      for (int x = domain.begin.x; x < domain.end.x; ++x)
        if (solid(rng)) w.voxels.set({x, y, z}, static_cast<std::uint8_t>(1 + rng() % 3));

  DistanceOptions o;
  o.metric = k.metric;
  o.signed_distance = k.is_signed;
  o.max_distance = k.clamp;
  o.storage = k.storage;
  o.nearest_sites = k.sites;
  o.spacing = k.spacing;
  o.domain = domain;
  const DistanceField whole = compute_distance_field(w.voxels, o);

  // Cut points: 1..5 slabs, some of one slice.
  const int pieces = 1 + static_cast<int>(rng() % 5);
  std::vector<int> cuts{domain.begin.z, domain.end.z};
  for (int i = 1; i < pieces; ++i) {
    cuts.push_back(domain.begin.z + 1 + static_cast<int>(rng() % (size.z - 1)));
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());

  // Each slab sees only its own voxels.
  std::vector<World> parts;
  std::vector<ColumnSites> extremes;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const Box3i slab{{domain.begin.x, domain.begin.y, cuts[i]},
                     {domain.end.x, domain.end.y, cuts[i + 1]}};
    World part(edge, slab);
    part.voxels.copy_from_dense(slab, dense(w.voxels, slab).data());
    extremes.push_back(slab_column_sites(part.voxels, domain, cuts[i], cuts[i + 1]));
    parts.push_back(std::move(part));
  }
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const Box3i slab{{domain.begin.x, domain.begin.y, cuts[i]},
                     {domain.end.x, domain.end.y, cuts[i + 1]}};
    const DistanceField f = compute_slab_distance_field(parts[i].voxels, o, cuts[i], cuts[i + 1],
                                                        neighbours_of(extremes, i));
    const std::string what = std::string(metric_name(k.metric)) + (k.is_signed ? " signed" : "") +
                             " clamp " + std::to_string(k.clamp) + " " + storage_name(k.storage) +
                             (k.sites ? " sites" : "") + " seed " + std::to_string(seed) +
                             " slab " + to_string(slab);
    ASSERT_EQ(f.domain, slab) << what;
    EXPECT_EQ(f.encoding.scale, whole.encoding.scale) << what;
    EXPECT_EQ(f.encoding.bias, whole.encoding.bias) << what;
    std::visit(
        [&](const auto& g) {
          using G = std::decay_t<decltype(g)>;
          EXPECT_EQ(dense(g, slab), dense(std::get<G>(whole.values), slab)) << what;
        },
        f.values);
    ASSERT_EQ(f.sites.has_value(), k.sites) << what;
    if (k.sites) {
      EXPECT_EQ(dense(*f.sites, slab), dense(*whole.sites, slab)) << what;
    }
  }
}

TEST(SlabDistance, EverySlabEqualsTheWholeField) {
  std::uint32_t seed = 1;
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool sgn : {false, true})
      for (double clamp : {0.0, 3.5})
        for (Storage st : {Storage::kF32, Storage::kU8, Storage::kU16})
          for (bool sites : {false, true})
            for (double density : {0.004, 0.2, 0.93}) {
              check_slabs({m, sgn, clamp, st, sites}, seed, density, seed % 2 ? 8 : 16);
              ++seed;
            }
}

TEST(SlabDistance, AnisotropicSpacingAndWideClamps) {
  std::uint32_t seed = 1000;
  for (bool sgn : {false, true})
    for (double clamp : {0.0, 2.0, 40.0})
      for (bool sites : {false, true}) {
        check_slabs({Metric::kEuclidean, sgn, clamp, Storage::kF32, sites, {0.5, 1.25, 2.0}}, seed,
                    0.01, 8);
        check_slabs({Metric::kEuclidean, sgn, clamp, Storage::kU16, sites, {1.0, 0.75, 0.5}},
                    seed + 1, 0.05, 16);
        seed += 2;
      }
}

TEST(SlabDistance, RefusesBadSlabsAndNeighbours) {
  const Box3i domain{{0, 0, 0}, {4, 3, 10}};
  World w(8, domain);
  w.voxels.set({1, 1, 5}, 1);
  DistanceOptions o;
  SlabNeighbours n;
  const std::size_t cols = 12;
  n.solid_below.assign(cols, ColumnSites::kNoneHigh);
  n.air_below.assign(cols, ColumnSites::kNoneHigh);
  n.solid_above.assign(cols, ColumnSites::kNoneLow);
  n.air_above.assign(cols, ColumnSites::kNoneLow);
  EXPECT_THROW(compute_slab_distance_field(w.voxels, o, 2, 5, n), InvalidArgument);  // no domain
  o.domain = domain;
  EXPECT_NO_THROW(compute_slab_distance_field(w.voxels, o, 2, 5, n));
  EXPECT_THROW(compute_slab_distance_field(w.voxels, o, 5, 5, n), InvalidArgument);   // empty
  EXPECT_THROW(compute_slab_distance_field(w.voxels, o, 8, 11, n), InvalidArgument);  // outside
  SlabNeighbours short_n = n;
  short_n.air_above.pop_back();
  EXPECT_THROW(compute_slab_distance_field(w.voxels, o, 2, 5, short_n), InvalidArgument);
  SlabNeighbours inside = n;
  inside.solid_below[3] = 3;  // within the slab 2..5: not below it
  EXPECT_THROW(compute_slab_distance_field(w.voxels, o, 2, 5, inside), InvalidArgument);
  SlabNeighbours beyond = n;
  beyond.air_above[0] = 10;  // past the domain
  EXPECT_THROW(compute_slab_distance_field(w.voxels, o, 2, 5, beyond), InvalidArgument);
  EXPECT_THROW(slab_column_sites(w.voxels, domain, 4, 2), InvalidArgument);
  EXPECT_THROW(slab_column_sites(w.voxels, domain, 0, 11), InvalidArgument);
}

}  // namespace
}  // namespace voxfield
