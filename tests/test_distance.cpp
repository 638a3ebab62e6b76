// Exact distance fields against a brute-force oracle: random worlds of odd sizes, every metric,
// signed and unsigned, clamped and not, anisotropic spacing, every storage, several chunk edges and
// thread counts, nearest sites with the documented tie-breaking rule; plus tiny hand-made worlds
// with figures worked out by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <tuple>

#include "backends.h"
#include "voxfield/distance.h"
#include "voxfield/image.h"
#include "voxfield/parallel.h"

using namespace voxfield;
using namespace voxfield::testing_backends;

namespace {

// The oracle. For every voxel of `domain`, scan every site and keep the best by the documented
// key: smallest distance; then smallest site y; then smallest distance within the site's y-plane
// (the x-z part of the offset); then smallest site x; then smallest |dz|; then smallest site z.
struct OracleResult {
  double distance;  // signed when requested; +inf when no site
  bool has_site;
  SiteOffset site;
  double cost;  // squared distance for Euclidean
};

double metric_cost(Metric m, const std::array<double, 3>& sp, int dx, int dy, int dz) {
  const double ax = std::abs(dx) * sp[0], ay = std::abs(dy) * sp[1], az = std::abs(dz) * sp[2];
  switch (m) {
    case Metric::kManhattan:
      return ax + ay + az;
    case Metric::kChebyshev:
      return std::max({ax, ay, az});
    case Metric::kEuclidean:
      return ax * ax + ay * ay + az * az;
  }
  return 0;
}

std::vector<OracleResult> oracle(const std::vector<char>& solid, const Box3i& domain,
                                 const DistanceOptions& o) {
  const Vec3i n = domain.size();
  auto idx = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * n.y + y) * n.x + x; };
  std::vector<Vec3i> solids, airs;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) (solid[idx(x, y, z)] ? solids : airs).push_back({x, y, z});
  std::vector<OracleResult> out(solid.size());
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x) {
        const bool inside = solid[idx(x, y, z)];
        OracleResult r{std::numeric_limits<double>::infinity(), false, {}, 0};
        if (inside && !o.signed_distance) {
          r = {0.0, true, {0, 0, 0}, 0};
          out[idx(x, y, z)] = r;
          continue;
        }
        const auto& sites = inside ? airs : solids;
        std::tuple<double, int, double, int, int, int> best{1e300, 0, 0, 0, 0, 0};
        for (const Vec3i s : sites) {
          const int dx = s.x - x, dy = s.y - y, dz = s.z - z;
          const std::tuple<double, int, double, int, int, int> key{
              metric_cost(o.metric, o.spacing, dx, dy, dz),
              s.y,
              metric_cost(o.metric, o.spacing, dx, 0, dz),
              s.x,
              std::abs(dz),
              s.z};
          if (key < best) {
            best = key;
            r.has_site = true;
            r.site = {static_cast<std::int16_t>(dx), static_cast<std::int16_t>(dy),
                      static_cast<std::int16_t>(dz)};
          }
        }
        if (r.has_site) {
          r.cost = std::get<0>(best);
          r.distance = o.metric == Metric::kEuclidean ? std::sqrt(r.cost) : r.cost;
        }
        out[idx(x, y, z)] = r;
      }
  return out;
}

std::uint64_t isqrt_ref(std::uint64_t v) {
  std::uint64_t r = 0;
  while ((r + 1) * (r + 1) <= v) ++r;
  return r;
}

// What the field must store for an oracle result, given the options.
double expected_stored(const OracleResult& r, bool inside, const DistanceOptions& o,
                       const DistanceField& f) {
  const double clamp =
      o.max_distance > 0 ? o.max_distance : std::numeric_limits<double>::infinity();
  const bool unit = o.spacing == std::array<double, 3>{1, 1, 1};
  double d = r.has_site ? r.distance : std::numeric_limits<double>::infinity();
  if (o.storage == Storage::kF32) {
    d = std::min(d, clamp);
    return static_cast<float>(inside && o.signed_distance ? -d : d);
  }
  const double type_max = o.storage == Storage::kU8 ? 255 : 65535;
  const double S = f.encoding.scale, bias = static_cast<double>(f.encoding.bias);
  const double range = (type_max - bias) / S;
  const double eff_clamp = std::min(clamp, range);
  const bool neg = inside && o.signed_distance;
  double scaled;
  if (d >= eff_clamp) {
    scaled = std::floor((neg ? -eff_clamp : eff_clamp) * S);
  } else if (o.metric == Metric::kEuclidean && unit) {
    const std::uint64_t v = static_cast<std::uint64_t>(r.cost) * static_cast<std::uint64_t>(S * S);
    const std::uint64_t q = isqrt_ref(v);
    scaled = neg ? -static_cast<double>(q + (q * q != v)) : static_cast<double>(q);
  } else {
    scaled = std::floor((neg ? -d : d) * S);
  }
  return std::clamp(scaled + bias, 0.0, type_max);
}

double stored_at(const DistanceField& f, Vec3i p) {
  return std::visit([&](const auto& g) { return static_cast<double>(g.get(p)); }, f.values);
}

struct Case {
  Metric metric;
  bool is_signed;
  double clamp;
  Storage storage;
  std::array<double, 3> spacing;
  int chunk_edge;
  int threads;
  bool sites =
      true;  // nearest sites too (without them, clamped Euclidean fields take other 2-D passes)
};

std::string describe(const Case& c) {
  return std::string(metric_name(c.metric)) + (c.is_signed ? " signed" : " unsigned") + " clamp " +
         std::to_string(c.clamp) + " " + storage_name(c.storage) + " spacing " +
         std::to_string(c.spacing[0]) + "," + std::to_string(c.spacing[1]) + "," +
         std::to_string(c.spacing[2]) + " edge " + std::to_string(c.chunk_edge) + " threads " +
         std::to_string(c.threads) + (c.sites ? " with sites" : "");
}

// Builds a random bounded world, runs the field on `backend` and compares every voxel and site
// with the oracle. The Vulkan backend takes unit spacing only (other cases are left out there).
void check_case(Backend backend, const Case& c, std::uint32_t seed, Vec3i size, double density) {
  const bool unit = c.spacing == std::array<double, 3>{1, 1, 1};
  if (backend == Backend::kVulkan && !unit) return;
  SCOPED_TRACE(std::string(backend_name(backend)) + " " + describe(c) + " seed " +
               std::to_string(seed));
  std::mt19937 rng(seed);
  const Box3i bounds{{-5, 3, -9}, Vec3i{-5, 3, -9} + size};
  World w(c.chunk_edge, bounds);
  std::vector<char> solid(static_cast<std::size_t>(bounds.volume()));
  std::size_t i = 0;
  for (int z = bounds.begin.z; z < bounds.end.z; ++z)
    for (int y = bounds.begin.y; y < bounds.end.y; ++y)
      for (int x = bounds.begin.x; x < bounds.end.x; ++x, ++i) {
        solid[i] = std::uniform_real_distribution<double>(0, 1)(rng) < density;
        if (solid[i]) w.voxels.set({x, y, z}, static_cast<std::uint8_t>(1 + rng() % 200));
      }
  DistanceOptions o;
  o.metric = c.metric;
  o.signed_distance = c.is_signed;
  o.max_distance = c.clamp;
  o.storage = c.storage;
  o.spacing = c.spacing;
  o.nearest_sites = c.sites;
  std::optional<ThreadLimit> limit;
  limit.emplace(c.threads);
  const DistanceField f = exact_field(backend, w, o);
  ASSERT_EQ(f.domain, bounds);
  const auto expect = oracle(solid, bounds, o);
  const double clamp = c.clamp > 0 ? c.clamp : std::numeric_limits<double>::infinity();
  int reported = 0;
  i = 0;
  for (int z = bounds.begin.z; z < bounds.end.z; ++z)
    for (int y = bounds.begin.y; y < bounds.end.y; ++y)
      for (int x = bounds.begin.x; x < bounds.end.x; ++x, ++i) {
        const Vec3i p{x, y, z};
        const OracleResult& r = expect[i];
        const double want = expected_stored(r, solid[i], o, f);
        const double got = stored_at(f, p);
        // Anisotropic Euclidean sums squares in another order than the oracle: allow rounding
        // (relative 1e-6 on the f32 value; one fixed-point step for integer storage). The GPU's
        // square root may differ by a few ulps (gpu::kF32Tolerance).
        const bool gpu_f32 = backend == Backend::kVulkan && c.storage == Storage::kF32;
        const double tol =
            gpu_f32 ? gpu::kF32Tolerance * std::max(1.0, std::abs(want))
            : unit  ? 0.0
                    : (c.storage == Storage::kF32 ? 1e-6 * std::max(1.0, std::abs(want)) : 1.0);
        if (!(std::abs(got - want) <= tol) &&
            !(std::isinf(got) && std::isinf(want) && got == want)) {
          if (reported++ < 5)
            ADD_FAILURE() << "value at " << to_string(p) << ": got " << got << " want " << want;
        }
        // Sites: exact offsets wherever the distance is within the clamp (ties make anisotropic
        // rounding ambiguous, so there only the distance to the reported site is checked).
        if (!c.sites) continue;
        const SiteOffset s = f.sites->get(p);
        const bool within = r.has_site && r.distance <= clamp;
        if (!within) {
          if (!s.none() && reported++ < 5)
            ADD_FAILURE() << "site at " << to_string(p) << " should be none";
          continue;
        }
        if (solid[i] && !c.is_signed) {
          if (!(s == SiteOffset{0, 0, 0}) && reported++ < 5)
            ADD_FAILURE() << "solid voxel site not itself";
          continue;
        }
        if (unit) {
          if (!(s == r.site) && reported++ < 5) {
            ADD_FAILURE() << "site at " << to_string(p) << ": got " << s.dx << "," << s.dy << ","
                          << s.dz << " want " << r.site.dx << "," << r.site.dy << "," << r.site.dz;
          }
        } else if (!s.none()) {
          const double d = std::sqrt(metric_cost(c.metric, c.spacing, s.dx, s.dy, s.dz));
          if (std::abs(d - r.distance) > 1e-9 * std::max(1.0, r.distance) && reported++ < 5) {
            ADD_FAILURE() << "site at " << to_string(p) << " is at " << d << ", nearest at "
                          << r.distance;
          }
        } else if (reported++ < 5) {
          ADD_FAILURE() << "missing site at " << to_string(p);
        }
      }
  EXPECT_EQ(reported, 0);

  // The same distances written straight into a dense array (compute_distance_field_into), in
  // double: x fastest, or z fastest (as a Fortran-ordered NumPy array of (z, y, x) would be).
  if (backend != Backend::kCpu) return;
  DistanceOptions dense_o = o;
  dense_o.nearest_sites = false;
  const Vec3i n = bounds.size();
  const bool z_fastest = seed % 2 == 1;
  const std::array<std::ptrdiff_t, 3> stride =
      z_fastest ? std::array<std::ptrdiff_t, 3>{std::ptrdiff_t{n.z} * n.y, n.z, 1}
                : std::array<std::ptrdiff_t, 3>{1, n.x, std::ptrdiff_t{n.x} * n.y};
  std::vector<double> dense(static_cast<std::size_t>(bounds.volume()), -12345.0);
  compute_distance_field_into(w.voxels, dense_o, DenseDistances<double>{dense.data(), stride});
  i = 0;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x, ++i) {
        const OracleResult& r = expect[i];
        const bool neg = solid[i] && c.is_signed;
        const double d = r.has_site ? std::min(r.distance, clamp) : clamp;
        const double want = neg ? -d : d;
        const double got = dense[x * stride[0] + y * stride[1] + z * stride[2]];
        const double tol = unit ? 0.0 : 1e-9 * std::max(1.0, std::abs(want));
        if (!(std::abs(got - want) <= tol) && !(std::isinf(got) && got == want) && reported++ < 5) {
          ADD_FAILURE() << "dense value at " << x << "," << y << "," << z << ": got " << got
                        << " want " << want;
        }
      }
  EXPECT_EQ(reported, 0);
}

}  // namespace

class ExactDistanceOn : public ::testing::TestWithParam<Backend> {};
INSTANTIATE_TEST_SUITE_P(Backends, ExactDistanceOn,
                         ::testing::Values(Backend::kCpu, Backend::kVulkan), backend_test_name);

TEST_P(ExactDistanceOn, RandomWorldsAgainstBruteForce) {
  const Backend b = GetParam();
  VOXFIELD_SKIP_UNLESS_BACKEND(b);
  // Under a sanitizer the Vulkan backend checks a third of the cases (its host code takes the
  // same path for each, and the shaders run in lavapipe, which is not instrumented), picked by a
  // hash of the seed so that no loop's variable lines up with the pick; the optimised build checks
  // them all on both backends.
  const auto check_case = [b](const Case& c, std::uint32_t seed, Vec3i size, double density) {
    if (b == Backend::kVulkan && kSanitizedBuild && (seed * 2654435761u >> 16) % 3 != 0) return;
    ::check_case(b, c, seed, size, density);
  };
  const std::array<double, 3> unit{1, 1, 1}, aniso{0.5, 1.25, 2.0};
  std::uint32_t seed = 1;
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (bool sgn : {false, true})
      for (double clamp : {0.0, 3.5, 7.0})
        for (Storage st : {Storage::kF32, Storage::kU8, Storage::kU16}) {
          const int edge = (seed % 3 == 0) ? 8 : (seed % 3 == 1 ? 16 : 32);
          const int threads = seed % 2 ? 2 : 1;
          const double density =
              (seed % 4 == 0) ? 0.02 : (seed % 4 == 1 ? 0.1 : (seed % 4 == 2 ? 0.3 : 0.6));
          check_case({m, sgn, clamp, st, unit, edge, threads}, seed, {23, 17, 19}, density);
          // Clamped unit-spacing Euclidean fields without sites: truncated min-convolutions.
          if (m == Metric::kEuclidean && clamp > 0)
            check_case({m, sgn, clamp, st, unit, edge, threads, false}, seed + 1000, {23, 17, 19},
                       density);
          ++seed;
        }
  // Unit-spacing Euclidean fields without sites, unclamped or with a clamp beyond the truncated
  // passes' reach: windowed min-plus, the envelope for the lines left over from groups of eight,
  // and (in the sparse world with lines of 200, longer than the windows' budget of 96 steps per
  // voxel can cover) groups whose windows grow too wide.
  for (bool sgn : {false, true})
    for (double clamp : {0.0, 80.0})
      for (double density : {0.004, 0.05, 0.5}) {
        const Storage st = seed % 2 ? Storage::kF32 : Storage::kU16;
        check_case(
            {Metric::kEuclidean, sgn, clamp, st, unit, 16, 1 + static_cast<int>(seed % 2), false},
            seed, {23, 17, 19}, density);
        if (density < 0.01)
          check_case({Metric::kEuclidean, sgn, clamp, st, unit, 32, 2, false}, seed + 2000,
                     {200, 27, 5}, density / 8);
        ++seed;
      }
  for (bool sgn : {false, true})
    for (double clamp : {0.0, 4.0})
      for (Storage st : {Storage::kF32, Storage::kU16}) {
        check_case({Metric::kEuclidean, sgn, clamp, st, aniso, 8, 2}, seed, {21, 13, 17}, 0.05);
        ++seed;
      }
  // Spacings that are not dyadic fractions (1.2, 0.7): the envelope's separations are rounded
  // divisions, and at an exact tie one came out a hair low — an empty stretch in the lower
  // envelope that handed every voxel before it the wrong site (found against SciPy's
  // distance_transform_edt with sampling (0.5, 1.2, 2.0), a distance off by 1.56 on an 11 x 19 x 2
  // volume of three sites; planted here as it was found, then at random).
  {
    const std::array<double, 3> odd{0.5, 1.2, 1.0};
    World w(8, Box3i::from_size({11, 19, 2}));
    for (const Vec3i p : {Vec3i{2, 14, 0}, Vec3i{8, 13, 0}, Vec3i{10, 16, 0}}) w.voxels.set(p, 1);
    DistanceOptions o;
    o.metric = Metric::kEuclidean;
    o.spacing = odd;
    const DistanceField f = compute_distance_field(w, o);
    // (6, 0, 0) is nearest to (8, 13, 0): sqrt((2 * 0.5)^2 + (13 * 1.2)^2).
    EXPECT_NEAR(f.distance({6, 0, 0}), std::sqrt(1.0 + 13 * 13 * 1.44), 1e-5);
  }
  const std::array<double, 3> odd{0.7, 1.2, 1.9};
  for (bool sgn : {false, true})
    for (double density : {0.01, 0.05, 0.2}) {
      check_case({Metric::kEuclidean, sgn, 0.0, Storage::kF32, odd, 8, 2}, seed, {29, 23, 11},
                 density);
      ++seed;
    }
  expect_no_validation_messages(b);
}

TEST(ExactDistance, IdenticalForEveryChunkEdgeAndThreadCount) {
  std::mt19937 rng(77);
  const Box3i bounds{{0, 0, 0}, {45, 38, 70}};
  for (Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean}) {
    std::vector<float> reference;
    for (int edge : {8, 16, 32, 64, 128}) {
      for (int threads : {1, 2}) {
        World w(edge, bounds);
        std::mt19937 r2(5);
        for (int k = 0; k < 300; ++k) {
          w.voxels.set({static_cast<int>(r2() % 45), static_cast<int>(r2() % 38),
                        static_cast<int>(r2() % 70)},
                       1);
        }
        DistanceOptions o;
        o.metric = m;
        o.signed_distance = true;
        ThreadLimit limit(threads);
        const DistanceField f = compute_distance_field(w, o);
        std::vector<float> dense(static_cast<std::size_t>(bounds.volume()));
        std::get<Grid<float>>(f.values).copy_to_dense(bounds, dense.data());
        if (reference.empty()) {
          reference = dense;
        } else {
          EXPECT_EQ(dense, reference)
              << metric_name(m) << " edge " << edge << " threads " << threads;
        }
      }
    }
  }
}

TEST(ExactDistance, EmptyAndFullWorlds) {
  const Box3i bounds{{0, 0, 0}, {20, 9, 11}};
  World empty(16, bounds);
  for (Storage st : {Storage::kF32, Storage::kU8, Storage::kU16}) {
    DistanceOptions o;
    o.storage = st;
    const DistanceField f = compute_distance_field(empty, o);
    const double v = stored_at(f, {3, 3, 3});
    if (st == Storage::kF32) {
      EXPECT_TRUE(std::isinf(v) && v > 0);
    } else {
      EXPECT_EQ(v, st == Storage::kU8 ? 255 : 65535);
    }
    o.max_distance = 5;
    EXPECT_EQ(compute_distance_field(empty, o).distance({3, 3, 3}), 5);
  }
  World full(16, bounds);
  full.voxels.fill(bounds, 4);
  DistanceOptions o;
  o.signed_distance = true;
  EXPECT_TRUE(std::isinf(compute_distance_field(full, o).distance({1, 1, 1})));
  EXPECT_LT(compute_distance_field(full, o).distance({1, 1, 1}), 0);
  o.max_distance = 3;
  EXPECT_EQ(compute_distance_field(full, o).distance({1, 1, 1}), -3);
  o.signed_distance = false;
  EXPECT_EQ(compute_distance_field(full, o).distance({1, 1, 1}), 0);
}

TEST(ExactDistance, HandWorkedFigures) {
  // One solid voxel at the origin of an unbounded world; the default domain is its box grown by
  // the clamp.
  World w;
  w.voxels.set({0, 0, 0}, 1);
  DistanceOptions o;
  o.max_distance = 10;
  o.metric = Metric::kManhattan;
  DistanceField f = compute_distance_field(w, o);
  EXPECT_EQ(f.domain, (Box3i{{-10, -10, -10}, {11, 11, 11}}));
  EXPECT_EQ(f.distance({3, -4, 2}), 9);
  EXPECT_EQ(f.distance({3, -4, 5}), 10);   // 12, clamped
  EXPECT_EQ(f.distance({500, 0, 0}), 10);  // outside the domain: the background D
  o.metric = Metric::kChebyshev;
  f = compute_distance_field(w, o);
  EXPECT_EQ(f.distance({3, -4, 2}), 4);
  o.metric = Metric::kEuclidean;
  f = compute_distance_field(w, o);
  EXPECT_FLOAT_EQ(static_cast<float>(f.distance({3, 4, 0})), 5.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(f.distance({1, 1, 1})), std::sqrt(3.0f));
  // Fixed point rounds down: sqrt(2) * 4 = 5.66 -> 5 -> 1.25 voxels, never above the truth.
  o.storage = Storage::kU8;
  f = compute_distance_field(w, o);
  EXPECT_EQ(std::get<Grid<std::uint8_t>>(f.values).get({1, 1, 0}), 5);
  EXPECT_EQ(f.distance({1, 1, 0}), 1.25);
  // Signed: a 3x3x3 solid cube; its centre is 2 from the nearest air voxel.
  World cube(8, Box3i{{-4, -4, -4}, {5, 5, 5}});
  cube.voxels.fill({{-1, -1, -1}, {2, 2, 2}}, 2);
  DistanceOptions s;
  s.signed_distance = true;
  s.metric = Metric::kEuclidean;
  s.nearest_sites = true;
  const DistanceField c = compute_distance_field(cube, s);
  EXPECT_EQ(c.distance({0, 0, 0}), -2);
  EXPECT_EQ(c.distance({1, 1, 1}), -1);
  EXPECT_EQ(c.distance({2, 0, 0}), 1);
  EXPECT_FLOAT_EQ(static_cast<float>(c.distance({2, 2, 2})), std::sqrt(3.0f));
  // Ties: the centre's nearest air voxels are the six face neighbours at distance 2; the rule
  // picks the smallest y first: (0, -2, 0).
  EXPECT_EQ(c.sites->get({0, 0, 0}), (SiteOffset{0, -2, 0}));
  // Signed integer storage is offset binary: 128 is the surface.
  s.storage = Storage::kU8;
  s.metric = Metric::kManhattan;
  const DistanceField ci = compute_distance_field(cube, s);
  EXPECT_EQ(std::get<Grid<std::uint8_t>>(ci.values).get({0, 0, 0}), 128 - 2);
  EXPECT_EQ(std::get<Grid<std::uint8_t>>(ci.values).get({3, 0, 0}), 128 + 2);
}

TEST(ExactDistance, VoxelsOutsideTheDomainInItsEdgeChunksReadTheBackground) {
  // An unbounded world's domain is its content box grown by the clamp (or one voxel): rarely
  // chunk-aligned, so its edge chunks hold voxels outside it. Those read the background like any
  // voxel beyond the domain, never what the passes left there (pass A used to store its raw
  // column distance in every lane of a chunk row, which f32 storage read as NaN or a denormal).
  World w;  // chunk edge 32; content in one chunk, the domain reaching into its neighbours
  for (const Vec3i p : {Vec3i{3, 5, 7}, Vec3i{9, 2, 2}, Vec3i{4, 12, 20}}) w.voxels.set(p, 1);
  for (const Metric m : {Metric::kManhattan, Metric::kChebyshev, Metric::kEuclidean})
    for (const Storage st : {Storage::kF32, Storage::kU8, Storage::kU16})
      for (const double clamp : {0.0, 6.0})
        for (const bool is_signed : {false, true})
          for (const bool with_sites : {false, true}) {
            DistanceOptions o;
            o.metric = m;
            o.storage = st;
            o.max_distance = clamp;
            o.signed_distance = is_signed;
            o.nearest_sites = with_sites;  // without: the truncated passes where the clamp allows
            const DistanceField f = compute_distance_field(w, o);
            const double background = f.distance({100000, 0, 0});  // in no chunk at all
            const std::string what = "metric " + std::to_string(static_cast<int>(m)) +
                                     ", storage " + std::to_string(static_cast<int>(st)) +
                                     ", clamp " + std::to_string(clamp) +
                                     (is_signed ? ", signed" : "");
            ASSERT_FALSE(std::isnan(background)) << what;
            int outside = 0;
            const int edge = f.chunk_edge();
            // Whole x rows across the edge chunks, at y and z just outside, on and inside the
            // domain.
            const Box3i d = f.domain;
            const int ys[] = {d.begin.y - 1, d.begin.y, (d.begin.y + d.end.y) / 2, d.end.y - 1,
                              d.end.y};
            const int zs[] = {d.begin.z - 1, d.begin.z, (d.begin.z + d.end.z) / 2, d.end.z - 1,
                              d.end.z};
            for (const int z : zs)
              for (const int y : ys)
                for (int x = -edge; x < 2 * edge; ++x) {
                  const Vec3i p{x, y, z};
                  if (f.domain.contains(p)) continue;
                  ++outside;
                  ASSERT_EQ(f.distance(p), background) << what << " at " << to_string(p);
                  if (with_sites) {
                    ASSERT_EQ(f.sites->get(p), SiteOffset{}) << what << " at " << to_string(p);
                  }
                }
            EXPECT_GT(outside, 0);
          }
}

TEST(ExactDistance, RejectsBadOptions) {
  World w;
  w.voxels.set({0, 0, 0}, 1);
  DistanceOptions o;
  o.max_distance = -1;
  EXPECT_THROW(compute_distance_field(w, o), InvalidArgument);
  o = {};
  o.spacing = {1, 0, 1};
  o.metric = Metric::kEuclidean;
  EXPECT_THROW(compute_distance_field(w, o), InvalidArgument);
  o.spacing = {1, 2, 1};
  o.metric = Metric::kManhattan;
  EXPECT_THROW(compute_distance_field(w, o), InvalidArgument);
  o = {};
  o.metric = Metric::kEuclidean;
  o.storage = Storage::kU8;
  o.spacing = {1, 1, 0.01};  // g along z would overflow u8 before reaching the clamp
  EXPECT_THROW(compute_distance_field(w, o), InvalidArgument);
  o = {};
  o.nearest_sites = true;
  o.domain = Box3i{{0, 0, 0}, {40000, 1, 1}};
  EXPECT_THROW(compute_distance_field(w, o), InvalidArgument);
  EXPECT_THROW(parse_metric("taxicab"), InvalidArgument);
}

TEST(ExactDistance, WideDomainsUseTheSixtyFourBitKernel) {
  // Squared distances beyond 2^29 select the 64-bit Euclidean kernel; check it on a long line.
  const int n = 24000;
  World w(8,
          Box3i::from_size(
              {n, 1, 1}));  // small chunks: a thin domain in 128^3 chunks would be mostly padding
  w.voxels.set({0, 0, 0}, 1);
  w.voxels.set({n - 1, 0, 0}, 1);
  w.voxels.set({9000, 0, 0}, 1);
  DistanceOptions o;
  o.metric = Metric::kEuclidean;
  o.nearest_sites = true;
  const DistanceField f = compute_distance_field(w, o);
  for (int x : {1, 4499, 4500, 4501, 8999, 16499, 16500, 16501, n - 2}) {
    const double want = std::min({std::abs(x - 0), std::abs(x - 9000), std::abs(x - (n - 1))});
    EXPECT_EQ(f.distance({x, 0, 0}), want) << x;
  }
  EXPECT_EQ(f.sites->get({4500, 0, 0}), (SiteOffset{-4500, 0, 0}));  // a tie: the smaller x wins
}

TEST(ExactDistance, ContentHashesPinResultsWhateverTheChunkEdge) {
  // The same field computed on grids of different chunk edges hashes the same; one changed value,
  // one changed site or another domain does not.
  const Box3i bounds{{-3, 0, 2}, {30, 21, 17}};
  std::uint64_t first = 0;
  for (int edge : {8, 16, 32}) {
    World w(edge, bounds);
    std::mt19937 place(5);
    for (int i = 0; i < 60; ++i)
      w.voxels.set({bounds.begin.x + static_cast<int>(place() % 33), static_cast<int>(place() % 21),
                    2 + static_cast<int>(place() % 15)},
                   1);
    DistanceOptions o;
    o.metric = Metric::kEuclidean;
    o.nearest_sites = true;
    DistanceField f = compute_distance_field(w, o);
    const std::uint64_t h = content_hash(f);
    if (edge == 8) first = h;
    EXPECT_EQ(h, first) << "edge " << edge;
    if (edge != 32) continue;
    const Vec3i p{4, 5, 6};
    DistanceField changed = f;
    std::get<Grid<float>>(changed.values).set(p, std::get<Grid<float>>(f.values).get(p) + 1);
    EXPECT_NE(content_hash(changed), h);
    DistanceField moved_site = f;
    moved_site.sites->set(p, SiteOffset{1, 2, 3});
    EXPECT_NE(content_hash(moved_site), h);
    DistanceField other_domain = f;
    other_domain.domain.end.x -= 1;
    EXPECT_NE(content_hash(other_domain), h);
  }
  Image a(4, 3), b(4, 3), c(3, 4);
  EXPECT_EQ(content_hash(a), content_hash(b));
  b.pixel(2, 1)[1] = 9;
  EXPECT_NE(content_hash(a), content_hash(b));
  EXPECT_NE(content_hash(a), content_hash(c)) << "the same bytes in another shape";
}
