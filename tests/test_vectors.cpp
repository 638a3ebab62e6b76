// Vector fields against their definition (docs/vectors.md): vector_at() in double precision is the
// oracle; brute force and splatting must equal it voxel for voxel, in every volume shape and for
// every kind of source; JFA's distance from it is measured; storage, decay, blend, scheduling and
// sampling against hand-worked values.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "error_text.h"
#include "vector_test_inputs.h"
#include "vectors/blend.h"            // internal: the four-lane rgba8 blend, tested against blend()
#include "vectors/vector_internal.h"  // internal: segment_t, tested against its definition
#include "voxfield/error.h"
#include "voxfield/vector_files.h"
#include "voxfield/vectors.h"

namespace voxfield {
using test::cube_volume;
using test::random_sources;
using test::Shape;
using test::shapes;
}  // namespace voxfield

namespace voxfield {
namespace {

using test::error_of;

std::vector<std::int32_t> oracle_winners(const VectorVolume& v, std::span<const VectorSource> s,
                                         VectorRule rule) {
  std::vector<std::int32_t> w(static_cast<std::size_t>(v.voxel_count()));
  for (int k = 0; k < v.resolution.z; ++k)
    for (int j = 0; j < v.resolution.y; ++j)
      for (int i = 0; i < v.resolution.x; ++i)
        w[static_cast<std::size_t>(v.index(i, j, k))] =
            vector_at(v.voxel_centre(i, j, k), s, rule).source;
  return w;
}

TEST(Vectors, BruteAndSplatEqualTheDefinitionEverywhere) {
  for (const Shape& shape : shapes()) {
    for (VectorRule rule : {VectorRule::kStrongest, VectorRule::kNearest}) {
      const std::vector<VectorSource> sources = random_sources(shape.volume, 40, 7);
      const auto want = oracle_winners(shape.volume, sources, rule);
      for (VectorAlgorithm a : {VectorAlgorithm::kBrute, VectorAlgorithm::kSplat}) {
        VectorOptions o;
        o.algorithm = a;
        o.rule = rule;
        const auto got = vector_winners(shape.volume, sources, o);
        std::int64_t differ = 0;
        for (std::size_t i = 0; i < want.size(); ++i) differ += got[i] != want[i];
        EXPECT_EQ(differ, 0) << shape.name << " " << vector_algorithm_name(a) << " "
                             << vector_rule_name(rule);
      }
      std::int64_t covered = 0;
      for (std::int32_t w : want) covered += w >= 0;
      EXPECT_GT(covered, 0) << shape.name;  // the test exercises something
    }
  }
}

TEST(Vectors, TexelsAreTheDefinitionsValuesInEveryStorage) {
  const VectorVolume v = shapes()[2].volume;  // rotated, anisotropic
  const std::vector<VectorSource> sources = random_sources(v, 25, 11);
  for (VectorStorage storage :
       {VectorStorage::kRgba32f, VectorStorage::kRgba16f, VectorStorage::kRgba8}) {
    const VectorTexture t = generate_vectors(v, sources, storage);
    // The largest rounding of a stored channel: float, half (2^-11 relative, below 1), 8 bits.
    const double tol = storage == VectorStorage::kRgba32f   ? 1e-6
                       : storage == VectorStorage::kRgba16f ? 1.0 / 1024
                                                            : 1.0 / 255 + 1e-6;
    double worst = 0;
    for (int k = 0; k < v.resolution.z; ++k)
      for (int j = 0; j < v.resolution.y; ++j)
        for (int i = 0; i < v.resolution.x; ++i) {
          const VectorValue want =
              vector_at(v.voxel_centre(i, j, k), sources, VectorRule::kStrongest);
          const VectorTexel got = t.get(v.index(i, j, k));
          const double e = std::max(
              {std::abs(got.x - want.direction.x), std::abs(got.y - want.direction.y),
               std::abs(got.z - want.direction.z), std::abs(got.strength - want.strength)});
          worst = std::max(worst, e);
        }
    EXPECT_LE(worst, tol) << vector_storage_name(storage);
  }
}

TEST(Vectors, DirectionPointsAwayFromTheSourceAndStationarySourcesAreFinite) {
  const VectorVolume v = cube_volume(8);  // voxel (i, j, k) centred at i - 3.5, ...
  const VectorSource s{{-3.5, -3.5, -3.5}, {-3.5, -3.5, -3.5}, 3.0};
  const VectorTexture t = generate_vectors(v, std::span(&s, 1), VectorStorage::kRgba32f);
  const VectorTexel at = t.get(v.index(0, 0, 0));  // the source's own voxel: d = 0
  EXPECT_EQ(at, (VectorTexel{0, 0, 0, 1}));
  const VectorTexel right = t.get(v.index(2, 0, 0));
  EXPECT_FLOAT_EQ(right.x, 1);  // away from the source, as the paper's formula
  EXPECT_FLOAT_EQ(right.strength, static_cast<float>(1 - 2.0 / 3.0));
  EXPECT_EQ(t.get(v.index(3, 0, 0)), VectorTexel{});  // d = 3 = r: not covered
}

TEST(Vectors, SubVoxelSourcesSurviveJumpFlooding) {
  const VectorVolume v = cube_volume(16);
  // Radius 0.3 voxel, off every centre but reaching one (0.2 from voxel (4,4,4)'s centre).
  const VectorSource s{{-3.5 + 0.2, -3.5, -3.5}, {-3.5 + 0.2, -3.5, -3.5}, 0.3};
  for (VectorAlgorithm a :
       {VectorAlgorithm::kJfa, VectorAlgorithm::kJfaPlus1, VectorAlgorithm::kJfaPlus2}) {
    VectorOptions o;
    o.algorithm = a;
    const auto w = vector_winners(v, std::span(&s, 1), o);
    EXPECT_EQ(w[static_cast<std::size_t>(v.index(4, 4, 4))], 0) << vector_algorithm_name(a);
  }
}

TEST(Vectors, JumpFloodingIsExactForOneSourceAndItsErrorIsMeasuredForMany) {
  const VectorVolume v = shapes()[1].volume;
  const std::vector<VectorSource> one = random_sources(v, 2, 3);  // the second: a fast mover
  VectorOptions exact, jfa;
  jfa.algorithm = VectorAlgorithm::kJfa;
  const std::span<const VectorSource> single(&one[1], 1);
  const VectorError e1 = compare_vector_winners(v, single, vector_winners(v, single, exact),
                                                vector_winners(v, single, jfa));
  EXPECT_EQ(e1.source_differs, 0);
  EXPECT_EQ(e1.max_strength_error, 0);

  const std::vector<VectorSource> many = random_sources(v, 60, 5);
  const auto want = vector_winners(v, many, exact);
  for (VectorAlgorithm a :
       {VectorAlgorithm::kJfa, VectorAlgorithm::kJfaPlus1, VectorAlgorithm::kJfaPlus2}) {
    jfa.algorithm = a;
    VectorPassTimes times;
    const VectorError e =
        compare_vector_winners(v, many, want, vector_winners(v, many, jfa, &times));
    EXPECT_EQ(e.voxels, v.voxel_count());
    EXPECT_LT(e.percent_differs(), 50) << vector_algorithm_name(a);  // a flood, not noise
    EXPECT_EQ(times.flood_passes,
              5 + (a == VectorAlgorithm::kJfaPlus1) + 2 * (a == VectorAlgorithm::kJfaPlus2));
    std::printf(
        "%s: %.3f %% of voxels take another source, max angle %.2f deg, max strength %.4f\n",
        vector_algorithm_name(a), e.percent_differs(), e.max_angle_deg, e.max_strength_error);
  }
  // The comparison itself is not blind: planted differences are counted.
  auto planted = want;
  int changed = 0;
  for (auto& w : planted)
    if (w >= 0 && changed < 5) w = -1, ++changed;
  EXPECT_EQ(compare_vector_winners(v, many, want, planted).source_differs, changed);
}

TEST(Vectors, StorageEncodingsAreTheDocumentedOnes) {
  VectorTexture t8(Vec3i{2, 1, 1}, VectorStorage::kRgba8);
  EXPECT_EQ(std::vector<std::uint8_t>(t8.bytes().begin(), t8.bytes().begin() + 4),
            (std::vector<std::uint8_t>{128, 128, 128, 0}));  // the zero texel
  t8.set(1, {1, -1, 0.5f, 0.5f});
  // (1+1)/2*255 = 255, 0, (1.5/2)*255 + 0.5 = 191.75 -> 191, 0.5 * 255 + 0.5 = 128.
  EXPECT_EQ(std::vector<std::uint8_t>(t8.bytes().begin() + 4, t8.bytes().end()),
            (std::vector<std::uint8_t>{255, 0, 191, 128}));
  VectorTexture t16(Vec3i{1, 1, 1}, VectorStorage::kRgba16f);
  t16.set(0, {1.0f, -2.0f, 65504.0f, 1.0f / 3});
  std::uint16_t h[4];
  std::memcpy(h, t16.bytes().data(), 8);
  EXPECT_EQ(h[0], 0x3c00);
  EXPECT_EQ(h[1], 0xc000);
  EXPECT_EQ(h[2], 0x7bff);
  EXPECT_EQ(h[3], 0x3555);  // 1/3 rounds to 0x3555 (nearest)
  // A tie rounds to even: 1 + 2^-11 lies halfway between 1 and 1 + 2^-10.
  t16.set(0, {1.0f + 1.0f / 2048, 1.0f + 3.0f / 2048, 1e-7f, 1e6f});
  std::memcpy(h, t16.bytes().data(), 8);
  EXPECT_EQ(h[0], 0x3c00);
  EXPECT_EQ(h[1], 0x3c02);
  EXPECT_EQ(h[2], 0x0002);  // subnormal: 1e-7 / 2^-24 = 1.68 -> 2
  EXPECT_EQ(h[3], 0x7c00);  // beyond the largest half: infinity
  EXPECT_EQ(t16.get(0).y, 1.0f + 1.0f / 512);
}

TEST(Vectors, DecayAndBlendMatchHandWorkedValues) {
  const VectorTexel cur{1, 0, 0, 0.6f}, prev{0, 1, 0, 0.5f};
  // Decay 1/s over 0.1 s leaves 0.4; w = 0.6; n = (0.6, 0.4, 0) normalised.
  const VectorTexel b = blend_vector_texels(cur, prev, 1.0, 0.1);
  const double len = std::sqrt(0.36 + 0.16);
  EXPECT_NEAR(b.x, 0.6 / len, 1e-6);
  EXPECT_NEAR(b.y, 0.4 / len, 1e-6);
  EXPECT_NEAR(b.strength, 0.6, 1e-6);
  EXPECT_EQ(blend_vector_texels({}, {}, 1.0, 0.1), VectorTexel{});    // 0 / 0 guarded
  const VectorTexel faded = blend_vector_texels({}, prev, 2.0, 0.1);  // no current source
  EXPECT_NEAR(faded.strength, 0.3, 1e-6);
  EXPECT_NEAR(faded.y, 1, 1e-6);
  EXPECT_EQ(blend_vector_texels({}, prev, 10.0, 0.1), VectorTexel{});  // fully decayed
  // Opposite directions of equal strength cancel: direction 0, strength kept.
  const VectorTexel cancel = blend_vector_texels({1, 0, 0, 0.5f}, {-1, 0, 0, 0.5f}, 0, 0.1);
  EXPECT_EQ(cancel, (VectorTexel{0, 0, 0, 0.5f}));
}

#if VOXFIELD_VECTORS_BLEND4
// The step's four-lane rgba8 blend against the definition, blend() then store(), on texels read
// from rgba8 bytes (the only texels it sees): every pair of strength bytes with random directions,
// random texels, and the cases that stress it — opposite directions cancelling, directions at the
// clamp (bytes 0 and 255), strengths that decay to a byte of 0 but not to 0.
TEST(Vectors, FourLaneRgba8BlendEqualsTheDefinitionBitForBit) {
  using detail::vectors::Codec;
  using detail::vectors::Rgba8Blend4;
  std::mt19937 rng(17);
  std::uniform_int_distribution<std::uint32_t> byte(0, 255), any;
  const auto decoded = [](std::uint32_t word) {
    std::uint8_t b[4];
    std::memcpy(b, &word, 4);
    return Codec<VectorStorage::kRgba8>::load(b);
  };
  std::int64_t checked = 0;
  for (const float decay_s : {0.0f, 1.0f / 255, 0.0174f, 0.25f, 0.99f}) {
    std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
    for (std::uint32_t sc = 1; sc < 256; ++sc)
      for (std::uint32_t sp = 1; sp < 256; ++sp)
        pairs.emplace_back((any(rng) & 0xffffffu) | sc << 24, (any(rng) & 0xffffffu) | sp << 24);
    for (int n = 0; n < 20000; ++n) {
      const std::uint32_t x = byte(rng), y = byte(rng), z = byte(rng);
      const std::uint32_t sc = 1 + byte(rng) % 255, sp = 1 + byte(rng) % 255;
      pairs.emplace_back(x | y << 8 | z << 16 | sc << 24,  // and its opposite, of any strength
                         (255 - x) | (255 - y) << 8 | (255 - z) << 16 | sp << 24);
      pairs.emplace_back((n % 2 ? 0u : 255u) | 128u << 8 | 128u << 16 | sc << 24,
                         (n % 3 ? 255u : 0u) | byte(rng) << 8 | 128u << 16 | sp << 24);
    }
    for (std::size_t first = 0; first < pairs.size(); first += 4) {
      const std::size_t count = std::min<std::size_t>(4, pairs.size() - first);
      std::uint32_t current[4], previous[4], out[4];
      for (std::size_t n = 0; n < 4; ++n)
        std::tie(current[n], previous[n]) = pairs[first + std::min(n, count - 1)];
      Rgba8Blend4::run(current, previous, decay_s, out);
      for (std::size_t n = 0; n < count; ++n) {
        const auto [c, p] = pairs[first + n];
        const VectorTexel previous = decoded(p);
        if (!(previous.strength - decay_s > 0)) continue;  // one-sided: not the lanes' case
        std::uint8_t want[4];
        Codec<VectorStorage::kRgba8>::store(want,
                                            detail::vectors::blend(decoded(c), previous, decay_s));
        std::uint32_t want_word;
        std::memcpy(&want_word, want, 4);
        ASSERT_EQ(out[n], want_word)
            << std::hex << "current " << c << " previous " << p << " decay " << decay_s;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 300000);
}
#endif

// segment_t divides only where the clamp may not decide; every pass (and the oracle) goes through
// it, so it is checked here against the clamp of the quotient itself, bit for bit (the sign of a
// zero included): random points, points whose projection lies exactly on and one ulp either side
// of -|ab|^2, 0 and |ab|^2, quotients that underflow, and a segment whose |ab|^2 overflows.
TEST(Vectors, SegmentParameterIsTheClampedQuotientBitForBit) {
  using detail::vectors::Segment;
  const auto definition = [](const Segment& s, Vec3d p) {
    return s.ab2 > 0 ? std::clamp(dot(p - s.a, s.ab) / s.ab2, 0.0, 1.0) : 0.0;
  };
  const auto same_bits = [](double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; };
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-2, 2);
  std::int64_t checked = 0;
  const auto check = [&](const Segment& s, Vec3d p) {
    const double got = detail::vectors::segment_t(s, p), want = definition(s, p);
    ASSERT_TRUE(same_bits(got, want) || (std::isnan(got) && std::isnan(want)))
        << "got " << got << " want " << want << " along " << dot(p - s.a, s.ab) << " ab2 " << s.ab2;
    ++checked;
  };
  for (int n = 0; n < 20000; ++n) {
    const Vec3d a{u(rng), u(rng), u(rng)}, b{u(rng) * 0.1, u(rng) * 0.1, u(rng) * 0.1};
    check(detail::vectors::segment_of({a + b, a, 0.5}), {u(rng), u(rng), u(rng)});
    // From a segment starting at x = 0, p = (x, a.y, a.z) has p - a = (x, 0, 0) exactly, so
    // dot(p - a, ab) = x * ab.x, rounded once: x chosen to land on and beside the boundaries.
    const Vec3d a0{0, a.y, a.z};
    const Segment s = detail::vectors::segment_of({a0 + b, a0, 0.5});
    if (s.ab.x == 0) continue;
    for (const double target : {-s.ab2, 0.0, s.ab2})
      for (const double x0 : {target / s.ab.x, -0.0, 1e-320})
        for (double x = std::nextafter(x0, -1e9), steps = 0; steps < 3;
             x = std::nextafter(x, 1e9), ++steps)
          check(s, {x, a.y, a.z});
  }
  // Quotients below the smallest double: -0 from the division, +0 from the clamp's shortcut
  // would differ.
  const Segment wide = detail::vectors::segment_of({{1e150, 0, 0}, {0, 0, 0}, 1});
  check(wide, {-1e-300, 0, 0});
  check(wide, {-0.0, 0, 0});
  check(wide, {2e150, 0, 0});
  // |ab|^2 overflows to infinity: the quotient is NaN or 0, never the shortcut's 1.
  const Segment huge = detail::vectors::segment_of({{1e200, 0, 0}, {-1e200, 0, 0}, 1});
  check(huge, {1e200, 0, 0});
  check(huge, {-1e200, 0, 0});
  check(huge, {0, 0, 0});
  EXPECT_GT(checked, 200000);
}

TEST(Vectors, SimulationStepsGenerateDecayAndBlend) {
  const VectorVolume v = cube_volume(16);
  VectorSimulation sim(v, VectorStorage::kRgba32f, {}, 2.0);
  const VectorSource s{{0, 0, 0}, {-4, 0, 0}, 3};
  sim.step(std::span(&s, 1), 0.1);
  for (std::int64_t i = 0; i < v.voxel_count(); ++i)
    ASSERT_EQ(sim.field().get(i), sim.current().get(i));
  sim.step({}, 0.1);  // the source has gone: its wake fades by 0.2
  for (std::int64_t i = 0; i < v.voxel_count(); ++i) ASSERT_EQ(sim.current().get(i), VectorTexel{});
  const std::int64_t centre = v.index(8, 8, 8);
  const VectorTexture first = generate_vectors(v, std::span(&s, 1), VectorStorage::kRgba32f);
  EXPECT_NEAR(sim.field().get(centre).strength, std::max(0.0f, first.get(centre).strength - 0.2f),
              1e-6);
  EXPECT_EQ(sim.steps(), 2);
  EXPECT_NE(error_of([&] { sim.step({}, 0); }).find("time step"), std::string::npos);
}

TEST(Vectors, TheSchedulerRunsWholeStepsCatchesUpAndCaps) {
  FixedStepScheduler f(0.25, 2);
  EXPECT_EQ(f.advance(0.1), 0);
  EXPECT_EQ(f.advance(0.2), 1);  // 0.3: one step, 0.05 left
  EXPECT_NEAR(f.pending_s(), 0.05, 1e-12);
  EXPECT_EQ(f.advance(1.0), 2);  // 1.05 is four steps' worth: two run, 0.5 s dropped
  EXPECT_NEAR(f.dropped_s(), 0.5, 1e-12);
  EXPECT_NEAR(f.pending_s(), 0.05, 1e-12);
  EXPECT_EQ(f.advance(0.2), 1);  // it catches up whole steps when the frame allows
  // Deterministic: the same frame times give the same steps.
  FixedStepScheduler a(1.0 / 60, 4), b(1.0 / 60, 4);
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> frame(0, 0.05);
  for (int i = 0; i < 1000; ++i) {
    const double t = frame(rng);
    ASSERT_EQ(a.advance(t), b.advance(t));
  }
  EXPECT_NE(error_of([] { FixedStepScheduler(0, 1); }).find("time step"), std::string::npos);
  EXPECT_NE(error_of([&] { f.advance(-1); }).find("frame time"), std::string::npos);
}

TEST(Vectors, SamplingIsTrilinearBetweenCentresAndZeroOutside) {
  VectorVolume v = shapes()[2].volume;  // rotated
  const std::vector<VectorSource> sources = random_sources(v, 20, 2);
  const VectorTexture t = generate_vectors(v, sources, VectorStorage::kRgba32f);
  for (const auto& [i, j, k] : {std::array{3, 2, 5}, std::array{0, 0, 0}, std::array{31, 7, 19}}) {
    const VectorSample s = sample_vectors(v, t, v.voxel_centre(i, j, k));
    const VectorTexel want = t.get(v.index(i, j, k));
    EXPECT_TRUE(s.inside);
    EXPECT_NEAR(s.strength, want.strength, 1e-9);
    EXPECT_NEAR(s.direction.x, want.x, 1e-9);
  }
  // Halfway between two centres along x: the mean.
  const Vec3d mid = (v.voxel_centre(10, 4, 6) + v.voxel_centre(11, 4, 6)) * 0.5;
  const VectorSample s = sample_vectors(v, t, mid);
  EXPECT_NEAR(s.strength,
              0.5 * (t.get(v.index(10, 4, 6)).strength + t.get(v.index(11, 4, 6)).strength), 1e-6);
  EXPECT_FALSE(sample_vectors(v, t, v.to_world({1.01, 0.5, 0.5})).inside);
  EXPECT_EQ(sample_vectors(v, t, v.to_world({-0.01, 0.5, 0.5})).strength, 0);
}

TEST(Vectors, BadVolumesAndSourcesAreRefusedByName) {
  VectorVolume v = cube_volume(8);
  const VectorSource ok{{0, 0, 0}, {0, 0, 0}, 1};
  v.resolution = {0, 8, 8};
  EXPECT_NE(error_of([&] {
              generate_vectors(v, std::span(&ok, 1), VectorStorage::kRgba8);
            }).find("resolution"),
            std::string::npos);
  v = cube_volume(8);
  v.size.y = std::nan("");
  EXPECT_NE(
      error_of([&] { generate_vectors(v, std::span(&ok, 1), VectorStorage::kRgba8); }).find("size"),
      std::string::npos);
  v = cube_volume(8);
  v.rotation[0] = {2, 0, 0};
  EXPECT_NE(error_of([&] { v.validate(); }).find("orthonormal"), std::string::npos);
  const VectorSource bad{{0, 0, 0}, {0, 0, 0}, -1};
  const VectorSource two[] = {ok, bad};
  EXPECT_NE(error_of([&] {
              generate_vectors(cube_volume(8), two, VectorStorage::kRgba8);
            }).find("source 1"),
            std::string::npos);
}

TEST(VectorFiles, SourcesFilesParseAndRefuseWithTheirPlace) {
  auto parse = [](const std::string& text) {
    return parse_vector_sources({reinterpret_cast<const std::uint8_t*>(text.data()), text.size()},
                                "s.json");
  };
  const VectorSourceFrames one = parse(R"({"sources": [{"position": [1, 2, 3], "radius": 2},
      {"position": [0, 0, 0], "previous": [-1, 0, 0], "radius": 0.5}]})");
  ASSERT_EQ(one.frames.size(), 1u);
  EXPECT_FALSE(one.animated);
  EXPECT_EQ(one.frames[0][0].previous, (Vec3d{1, 2, 3}));  // stationary by default
  EXPECT_EQ(one.frames[0][1].previous, (Vec3d{-1, 0, 0}));
  const VectorSourceFrames anim =
      parse(R"({"frames": [{"sources": []}, {"sources": [{"position": [0,0,0], "radius": 1}]}]})");
  EXPECT_TRUE(anim.animated);
  EXPECT_EQ(anim.frames.size(), 2u);
  const std::string syntax = error_of([&] { parse("{\"sources\": [\n{\"position\": }]}"); });
  EXPECT_NE(syntax.find("s.json: at byte"), std::string::npos) << syntax;
  EXPECT_NE(syntax.find("line 2"), std::string::npos) << syntax;
  const std::string radius = error_of([&] {
    parse(
        R"({"frames": [{"sources": []}, {"sources": [{"position": [0,0,0], "radius": 1}, {"position": [0,0,0], "radius": -2}]}]})");
  });
  EXPECT_NE(radius.find("s.json: frame 1, source 1: \"radius\" must be > 0"), std::string::npos)
      << radius;
  EXPECT_NE(error_of([&] {
              parse(R"({"sources": [{"position": [0,0,1e300], "radius": 1}]})");
            }).find("1e12"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              parse(R"({"sources": [{"position": [0,0], "radius": 1}]})");
            }).find("[x, y, z]"),
            std::string::npos);
  EXPECT_NE(error_of([&] { parse(R"({"sources": [], "frames": []})"); }).find("exactly one"),
            std::string::npos);
  EXPECT_NE(error_of([&] {
              parse(R"({"sources": [{"position": [0,0,0], "radius": 1, "speed": 3}]})");
            }).find("speed"),
            std::string::npos);
}

TEST(VectorFiles, UnrealAndUnityLayouts) {
  VectorVolume v = cube_volume(2);
  v.resolution = {2, 1, 1};
  v.size = {2, 1, 1};
  VectorTexture t(v.resolution, VectorStorage::kRgba32f);
  t.set(1, {0, 1, 0, 0.5f});
  EXPECT_EQ(encode_fga(v, t), "2,1,1,\n-1,-0.5,-0.5,\n1,0.5,0.5,\n0,0,0,\n0,0.5,0,\n");
  const std::vector<std::uint8_t> vf = encode_vf(v, t);
  ASSERT_EQ(vf.size(), 10u + 12u * 2u);
  EXPECT_EQ(std::string(vf.begin(), vf.begin() + 4), "VF_V");
  EXPECT_EQ(vf[4], 2);
  EXPECT_EQ(vf[6], 1);
  float y;
  std::memcpy(&y, vf.data() + 10 + 12 + 4, 4);
  EXPECT_EQ(y, 0.5f);
  VectorVolume big = cube_volume(129);
  VectorTexture tb(big.resolution, VectorStorage::kRgba8);
  EXPECT_NE(error_of([&] { encode_fga(big, tb); }).find("at most 128"), std::string::npos);
  const NpyVolume npy = vector_npy(t);
  EXPECT_EQ(npy.components, 4);
  float s;
  std::memcpy(&s, npy.bytes.data() + 4 * (3 * 2 + 1), 4);  // a[1, 0, 0, 3]
  EXPECT_EQ(s, 0.5f);
}

// The reactive sheet seen edge-on from its rest height (the fog made invisible): flat, it is a line
// no ray crosses; a source just above its middle pushes it down there — away from the source —
// so the dent shows below the horizon, under the source only, and never above it.
TEST(Vectors, TheSheetIsPushedAwayFromASource) {
  const VectorVolume v = cube_volume(32);  // 32 units across, centred at the origin
  const double rest = -16 + 0.3 * 32;
  VectorSource s;
  s.position = s.previous = {0, 0, rest + 3};
  s.radius = 6;
  VectorViewOptions view;
  view.width = 160;
  view.height = 121;  // an odd height: the middle row looks level along the sheet
  view.auto_eye = false;
  view.eye = {0, -80, rest};
  view.look_at = Vec3d{0, 0, rest};
  view.fov_deg = 30;
  view.density = 1e-9;
  view.sheet = true;
  view.sheet_push = 8;
  VectorViewOptions no_sheet = view;
  no_sheet.sheet = false;
  const VectorTexture zero(v.resolution, VectorStorage::kRgba16f);
  const Image none = render_vectors(v, zero, no_sheet);
  const Image flat = render_vectors(v, zero, view);
  const Image pushed =
      render_vectors(v, generate_vectors(v, std::span(&s, 1), VectorStorage::kRgba16f), view);
  auto drawn = [&](const Image& img, int x0, int x1, int y0, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y)
      for (int x = x0; x < x1; ++x) n += std::memcmp(img.pixel(x, y), none.pixel(x, y), 3) != 0;
    return n;
  };
  const int mid = view.height / 2, w = view.width;
  EXPECT_EQ(drawn(flat, 0, w, 0, view.height), 0) << "a flat sheet seen edge-on shows nothing";
  EXPECT_GT(drawn(pushed, w / 2 - 4, w / 2 + 4, mid + 1, view.height), 8) << "the dent, below";
  EXPECT_EQ(drawn(pushed, 0, w, 0, mid), 0) << "nothing pushed up";
  EXPECT_EQ(drawn(pushed, 0, 12, 0, view.height), 0) << "nothing far from the source";
  view.sheet_height = 1.5;
  EXPECT_THROW(render_vectors(v, zero, view), InvalidArgument);
}

TEST(Vectors, TheVisualiserShowsTheFieldAndNothingElse) {
  const VectorVolume v = cube_volume(24);
  VectorViewOptions view;
  view.width = 64;
  view.height = 48;
  const Image empty = render_vectors(v, VectorTexture(v.resolution, VectorStorage::kRgba8), view);
  for (std::size_t i = 3; i < empty.rgb.size(); ++i) ASSERT_EQ(empty.rgb[i], empty.rgb[i % 3]);
  const VectorSource s{{0, 0, 0}, {-6, 0, 0}, 6};
  const Image shown =
      render_vectors(v, generate_vectors(v, std::span(&s, 1), VectorStorage::kRgba8), view);
  int lit = 0;
  for (int y = 0; y < view.height; ++y)
    for (int x = 0; x < view.width; ++x) lit += shown.pixel(x, y)[0] != empty.pixel(x, y)[0];
  EXPECT_GT(lit, 50);
  EXPECT_EQ(shown.pixel(0, 0)[0], empty.pixel(0, 0)[0]);  // a corner ray misses the field
}

}  // namespace
}  // namespace voxfield

namespace voxfield {
namespace {

// Every storage's step (with rgba8's table of decayed strength bytes) against the definition
// applied texel by texel: generate, then blend_vector_texels with the stored previous field.
// Every algorithm: splatting's step fuses the search with the sweep, the others sweep the winners.
const VectorAlgorithm kEveryAlgorithm[] = {VectorAlgorithm::kBrute, VectorAlgorithm::kSplat,
                                           VectorAlgorithm::kJfa, VectorAlgorithm::kJfaPlus1,
                                           VectorAlgorithm::kJfaPlus2};

TEST(Vectors, StepsEqualGenerationThenBlendTexelByTexel) {
  const VectorVolume v = shapes()[2].volume;  // rotated, anisotropic
  for (VectorAlgorithm algorithm : kEveryAlgorithm)
    for (VectorStorage storage :
         {VectorStorage::kRgba8, VectorStorage::kRgba16f, VectorStorage::kRgba32f}) {
      SCOPED_TRACE(std::string(vector_algorithm_name(algorithm)) + " " +
                   vector_storage_name(storage));
      VectorOptions o;
      o.algorithm = algorithm;
      VectorSimulation sim(v, storage, o, 3.0);
      VectorTexture ref(v.resolution, storage);
      for (int step = 0; step < 8; ++step) {
        std::vector<VectorSource> sources = random_sources(v, step % 3 == 2 ? 0 : 6, 40 + step);
        sim.step(sources, 0.05);
        const VectorTexture cur = generate_vectors(v, sources, storage, o);
        for (std::int64_t i = 0; i < v.voxel_count(); ++i)
          ref.set(i, blend_vector_texels(cur.get(i), ref.get(i), 3.0, 0.05));
        ASSERT_TRUE(std::equal(ref.bytes().begin(), ref.bytes().end(), sim.field().bytes().begin()))
            << "step " << step;
        ASSERT_TRUE(
            std::equal(cur.bytes().begin(), cur.bytes().end(), sim.current().bytes().begin()));
      }
    }
}

// Wakes fading out with no source: at this decay an rgba8 strength byte of 5 decays to a strength
// above 0 that stores as byte 0 — a texel with a direction and no strength, which the next step
// must clear like any other (an early sweep flagged such rows empty and left them stale).
TEST(Vectors, FadingWakesEqualGenerationThenBlendToTheEnd) {
  const VectorVolume v = shapes()[1].volume;  // anisotropic
  const double dt = 1.0 / 60, decay = 4.6 / 255 / dt;
  for (VectorAlgorithm algorithm : {VectorAlgorithm::kSplat, VectorAlgorithm::kBrute})
    for (VectorStorage storage :
         {VectorStorage::kRgba8, VectorStorage::kRgba16f, VectorStorage::kRgba32f}) {
      SCOPED_TRACE(vector_algorithm_name(algorithm));
      VectorOptions o;
      o.algorithm = algorithm;
      VectorSimulation sim(v, storage, o, decay);
      VectorTexture ref(v.resolution, storage);
      for (int step = 0; step < 70; ++step) {
        const std::vector<VectorSource> sources =
            step < 2 ? random_sources(v, 10, 70 + step) : std::vector<VectorSource>{};
        sim.step(sources, dt);
        const VectorTexture cur = generate_vectors(v, sources, storage, o);
        for (std::int64_t i = 0; i < v.voxel_count(); ++i)
          ref.set(i, blend_vector_texels(cur.get(i), ref.get(i), decay, dt));
        ASSERT_TRUE(std::equal(ref.bytes().begin(), ref.bytes().end(), sim.field().bytes().begin()))
            << vector_storage_name(storage) << " step " << step;
      }
      EXPECT_TRUE(std::equal(ref.bytes().begin(), ref.bytes().end(),
                             VectorTexture(v.resolution, storage).bytes().begin()))
          << "every wake has faded";
    }
}

}  // namespace
}  // namespace voxfield
