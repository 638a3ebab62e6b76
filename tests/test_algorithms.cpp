// The dissertation's algorithm family against the exact transform: what must hold for each one
// (exactness where the method guarantees it, the side its errors fall on where it does not).
#include <gtest/gtest.h>

#include <random>

#include "voxfield/algorithms.h"
#include "voxfield/dissertation_format.h"

using namespace voxfield;

namespace {

World random_world(Vec3i size, double density, std::uint32_t seed, int edge = 16) {
  World w(edge, Box3i::from_size(size));
  std::mt19937 rng(seed);
  for (int z = 0; z < size.z; ++z)
    for (int y = 0; y < size.y; ++y)
      for (int x = 0; x < size.x; ++x)
        if (std::uniform_real_distribution<double>(0, 1)(rng) < density)
          w.voxels.set({x, y, z}, 1 + rng() % 9);
  return w;
}

FieldError run(const World& w, Metric m, Algorithm a, bool sgn = false,
               std::optional<Box3i> focus = {}, AlgorithmStats* stats = nullptr) {
  DistanceOptions o;
  o.metric = m;
  o.signed_distance = sgn;
  AlgorithmOptions ao;
  ao.algorithm = a;
  ao.focus = focus;
  const DistanceField exact = compute_distance_field(w, o);
  const DistanceField f = compute_distance_field(w, o, ao, stats);
  return compare_fields(f, exact, w);
}

}  // namespace

TEST(Algorithms, NamesRoundTrip) {
  for (Algorithm a : all_algorithms()) EXPECT_EQ(parse_algorithm(algorithm_name(a)), a);
  EXPECT_THROW(parse_algorithm("jfa+3"), InvalidArgument);
}

TEST(Algorithms, BruteForceIsExact) {
  const World w = random_world({19, 14, 11}, 0.05, 3);
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool sgn : {false, true}) {
      const FieldError e = run(w, m, Algorithm::kBrute, sgn);
      EXPECT_EQ(e.wrong, 0) << metric_name(m) << " signed " << sgn;
      EXPECT_GT(e.air_voxels, 0);
    }
  // It refuses work that would take hours.
  AlgorithmOptions ao;
  ao.algorithm = Algorithm::kBrute;
  ao.brute_max_work = 1000;
  EXPECT_THROW(compute_distance_field(w, DistanceOptions{}, ao), InvalidArgument);
}

TEST(Algorithms, FimAndHybridAreExactForManhattanAndChebyshev) {
  const World w = random_world({40, 37, 29}, 0.004, 5);
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev}) {
    for (Algorithm a : {Algorithm::kFim, Algorithm::kHybrid}) {
      AlgorithmStats stats;
      const FieldError e = run(w, m, a, false, {}, &stats);
      EXPECT_EQ(e.wrong, 0) << metric_name(m) << " " << algorithm_name(a);
      if (a == Algorithm::kFim) {
        EXPECT_GT(stats.iterations, 10) << metric_name(m);
      }
    }
    EXPECT_EQ(run(w, m, Algorithm::kFim, true).wrong, 0) << "signed " << metric_name(m);
  }
  // Plain JFA goes wrong on this world for Chebyshev, so there the hybrid's FIM has work to do.
  ASSERT_GT(run(w, Metric::kChebyshev, Algorithm::kJfa).wrong, 0);
  AlgorithmStats hybrid;
  EXPECT_EQ(run(w, Metric::kChebyshev, Algorithm::kHybrid, false, {}, &hybrid).wrong, 0);
  EXPECT_GT(hybrid.iterations, 0);
  // Euclidean FIM solves the eikonal equation: close to, not equal to, the exact distance.
  const FieldError e = run(w, Metric::kEuclidean, Algorithm::kFim);
  EXPECT_LT(e.max_over, 1.5);
  EXPECT_LT(e.max_under, 1.5);
}

TEST(Algorithms, JumpFloodingIsNeverTooSmallAndImprovesWithCorrections) {
  const World w = random_world({40, 37, 29}, 0.004, 5);
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
    AlgorithmStats s0, s2;
    const FieldError jfa = run(w, m, Algorithm::kJfa, false, {}, &s0);
    const FieldError jfa2 = run(w, m, Algorithm::kJfa2, false, {}, &s2);
    // Every value is the distance to a real site: at least the exact distance.
    EXPECT_EQ(jfa.too_small, 0) << metric_name(m);
    EXPECT_EQ(jfa2.too_small, 0) << metric_name(m);
    EXPECT_LE(jfa2.wrong, jfa.wrong) << metric_name(m);
    EXPECT_EQ(s2.passes, s0.passes + 2);
    EXPECT_EQ(s0.passes, 6);  // steps 32, 16, 8, 4, 2, 1 for a largest edge of 40
  }
}

TEST(Algorithms, DissertationJumpFloodingOverestimates) {
  // Propagating values instead of sites gives upper bounds that are often too large: unsafe for
  // a ray marcher. On sparse random sites a clear share of voxels is affected.
  const World w = random_world({48, 48, 48}, 0.002, 6);
  for (Metric m : {Metric::kManhattan, Metric::kEuclidean}) {
    const FieldError e = run(w, m, Algorithm::kJfaSeed);
    EXPECT_EQ(e.too_small, 0) << metric_name(m);
    EXPECT_GT(e.percent_unsafe(), 1.0) << metric_name(m);
    EXPECT_EQ(e.too_large, e.wrong);
  }
}

TEST(Algorithms, ChunkedBruteForceIsCappedAtChunkBorders) {
  const World w = random_world({64, 40, 33}, 0.001, 7, 16);
  const FieldError e = run(w, Metric::kManhattan, Algorithm::kBruteChunked);
  EXPECT_EQ(e.too_large, 0);  // the padding only adds sites
  EXPECT_GT(e.too_small, 0);  // ... which are too near
  // No voxel exceeds its distance to its chunk's border plus one.
  DistanceOptions o;
  AlgorithmOptions ao;
  ao.algorithm = Algorithm::kBruteChunked;
  const DistanceField f = compute_distance_field(w, o, ao);
  for (int x = 0; x < 64; ++x) {
    const int to_border = std::min(x % 16, 15 - x % 16) + 1;
    EXPECT_LE(f.distance({x, 8, 8}), std::min(to_border, std::min(8 % 16, 15 - 8 % 16) + 1)) << x;
  }
}

TEST(Algorithms, LevelOfDetailIsExactInsideTheFocus) {
  // docs/distance.md: lod is exact for L1 and L-infinity in the chunks meeting the focus box, and
  // JFA's field elsewhere; for Euclidean, FIM's passes only ever lower JFA's values in the focus
  // (its local rule approximates the eikonal equation and may fall below the exact distance).
  const World w = random_world({64, 48, 32}, 0.02, 8, 16);
  std::int64_t repaired = 0;  // focus voxels where JFA is wrong and lod exact
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
    DistanceOptions o;
    o.metric = m;
    const DistanceField exact = compute_distance_field(w, o);
    AlgorithmOptions ao;
    ao.algorithm = Algorithm::kLod;
    ao.focus = Box3i{{20, 20, 5}, {30, 25, 10}};  // chunks x 16..31, y 16..31, z 0..15
    const DistanceField lod = compute_distance_field(w, o, ao);
    ao.algorithm = Algorithm::kJfa;
    const DistanceField jfa = compute_distance_field(w, o, ao);
    for (int z = 0; z < 32; ++z)
      for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 64; ++x) {
          const Vec3i p{x, y, z};
          const std::string where = std::string(metric_name(m)) + " at " + std::to_string(x) + "," +
                                    std::to_string(y) + "," + std::to_string(z);
          const bool focus_chunk = x >= 16 && x < 32 && y >= 16 && y < 32 && z < 16;
          if (!focus_chunk) {
            ASSERT_EQ(lod.distance(p), jfa.distance(p)) << where;
          } else if (m == Metric::kEuclidean) {
            ASSERT_LE(lod.distance(p), jfa.distance(p)) << where;  // (FIM's L2 may undershoot)
          } else {
            ASSERT_EQ(lod.distance(p), exact.distance(p)) << where;
            repaired += jfa.distance(p) != exact.distance(p);
          }
        }
  }
  EXPECT_GT(repaired, 0) << "this world never exercises FIM's repair of JFA in the focus";
  EXPECT_THROW(
      compute_distance_field(w, DistanceOptions{}, AlgorithmOptions{Algorithm::kLod, std::nullopt}),
      InvalidArgument);
}

TEST(Algorithms, CompareReportsNothingForTheExactField) {
  const World w = random_world({20, 20, 20}, 0.05, 9);
  const FieldError e = run(w, Metric::kEuclidean, Algorithm::kExact, true);
  EXPECT_EQ(e.wrong, 0);
  EXPECT_EQ(e.voxels, 8000);
  EXPECT_EQ(e.air_voxels, 8000);  // signed: every voxel is measured
}

TEST(Algorithms, CompareCountsAndSizesPlantedErrors) {
  // Errors planted in a copy of the exact field, each of a known kind and size.
  const World w = random_world({20, 20, 20}, 0.05, 9);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  const DistanceField exact = compute_distance_field(w, o);
  std::vector<Vec3i> air;
  Vec3i solid{-1, -1, -1};
  std::int64_t air_count = 0;
  for (int z = 0; z < 20; ++z)
    for (int y = 0; y < 20; ++y)
      for (int x = 0; x < 20; ++x) {
        if (w.voxels.get({x, y, z}) != 0) {
          solid = {x, y, z};
          continue;
        }
        ++air_count;
        if (air.size() < 3 && exact.distance({x, y, z}) > 2) air.push_back({x, y, z});
      }
  ASSERT_EQ(air.size(), 3u);
  ASSERT_GE(solid.x, 0);
  DistanceField approx = exact;
  auto& g = std::get<Grid<float>>(approx.values);
  const auto d = [&](Vec3i p) { return static_cast<float>(exact.distance(p)); };
  g.set(air[0], d(air[0]) + 2.5f);         // too large: unsafe to march
  g.set(air[1], d(air[1]) - 1.25f);        // too small
  g.set(air[2], d(air[2]) * (1 + 5e-5f));  // within f32's 1e-4 tolerance
  g.set(solid, 3.0f);                      // a site: unsigned fields skip them
  const FieldError e = compare_fields(approx, exact, w);
  EXPECT_EQ(e.voxels, 8000);
  EXPECT_EQ(e.air_voxels, air_count);
  EXPECT_EQ(e.wrong, 2);
  EXPECT_EQ(e.too_large, 1);
  EXPECT_EQ(e.too_small, 1);
  EXPECT_NEAR(e.max_over, 2.5, 1e-5);
  EXPECT_NEAR(e.max_under, 1.25, 1e-5);
  EXPECT_DOUBLE_EQ(e.percent_wrong(), 200.0 / static_cast<double>(air_count));
  EXPECT_DOUBLE_EQ(e.percent_unsafe(), 100.0 / static_cast<double>(air_count));

  // Fixed point: half a step either way is the same stored value; a whole step is an error.
  o.storage = Storage::kU8;
  const DistanceField exact8 = compute_distance_field(w, o);
  DistanceField approx8 = exact8;
  auto& g8 = std::get<Grid<std::uint8_t>>(approx8.values);
  g8.set(air[0], static_cast<std::uint8_t>(g8.get(air[0]) + 1));
  const FieldError e8 = compare_fields(approx8, exact8, w);
  EXPECT_EQ(e8.wrong, 1);
  EXPECT_EQ(e8.too_large, 1);
  EXPECT_NEAR(e8.max_over, 1.0 / exact8.encoding.scale, 1e-12);
}

TEST(Algorithms, DissertationPackedFormat) {
  World w(8, Box3i::from_size({4, 1, 1}));
  w.palette[3] = {255, 0, 255, 255};  // RGB332: 111 000 11
  w.voxels.set({0, 0, 0}, 3);
  DistanceOptions o;
  const DistanceField f = compute_distance_field(w, o);
  const auto packed = pack_dissertation_format(w, f, Box3i::from_size({4, 1, 1}));
  ASSERT_EQ(packed.size(), 4u);
  EXPECT_EQ(packed[0], 0xE3u);           // distance 0, colour 0b11100011
  EXPECT_EQ(packed[3], (3u << 8) | 0u);  // air three voxels away
}
