// The voxel compiler against its definitions (docs/csg.md): every exact shape against a
// brute-force distance to its boundary found from an elementary inside test on a fine grid; the
// model language's values and errors on hand-worked models; the tape equal to the reference
// evaluation on random models; clipping sound on random models and cells (pruned tapes equal the
// whole tape bit for bit, empty and full cells free of surface); the octree, voxelisation and the
// generated GLSL.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "csg_examples.h"
#include "error_text.h"
#include "voxfield/csg.h"
#include "voxfield/csg_compile.h"

namespace voxfield::csg {
namespace {

using test::error_of;

Model parse(const std::string& text) {
  return parse_model(text, "test.sdf");
}

// The distance from p to the boundary of {inside}, by brute force: the boundary is located
// between neighbouring samples of a grid of spacing h over `box` that disagree, so the answer is
// within about h of the truth.
class BruteDistance {
 public:
  BruteDistance(const std::function<bool(Vec3d)>& inside, Bounds box, double h) : inside_(inside) {
    const int nx = static_cast<int>((box.hi.x - box.lo.x) / h) + 1,
              ny = static_cast<int>((box.hi.y - box.lo.y) / h) + 1,
              nz = static_cast<int>((box.hi.z - box.lo.z) / h) + 1;
    std::vector<char> in(static_cast<std::size_t>(nx) * ny * nz);
    auto at = [&](int x, int y, int z) { return box.lo + Vec3d{x * h, y * h, z * h}; };
    auto idx = [&](int x, int y, int z) { return (static_cast<std::size_t>(z) * ny + y) * nx + x; };
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) in[idx(x, y, z)] = inside(at(x, y, z));
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          if (x + 1 < nx && in[idx(x, y, z)] != in[idx(x + 1, y, z)])
            boundary_.push_back(at(x, y, z) + Vec3d{h / 2, 0, 0});
          if (y + 1 < ny && in[idx(x, y, z)] != in[idx(x, y + 1, z)])
            boundary_.push_back(at(x, y, z) + Vec3d{0, h / 2, 0});
          if (z + 1 < nz && in[idx(x, y, z)] != in[idx(x, y, z + 1)])
            boundary_.push_back(at(x, y, z) + Vec3d{0, 0, h / 2});
        }
  }
  double signed_distance(Vec3d p) const {
    double best = 1e300;
    for (const Vec3d& b : boundary_) best = std::min(best, dot(p - b, p - b));
    return inside_(p) ? -std::sqrt(best) : std::sqrt(best);
  }

 private:
  std::function<bool(Vec3d)> inside_;
  std::vector<Vec3d> boundary_;
};

double len2(double x, double y) {
  return std::sqrt(x * x + y * y);
}

struct ShapeCase {
  std::string text;
  std::function<bool(Vec3d)> inside;  // elementary, independent of the distance formulas
  Bounds box;
};

std::vector<ShapeCase> shape_cases() {
  return {
      {"(sphere 0.8)", [](Vec3d p) { return p.length() <= 0.8; }, {{-1, -1, -1}, {1, 1, 1}}},
      {"(box 1.6 1 0.6)",
       [](Vec3d p) { return std::abs(p.x) <= 0.8 && std::abs(p.y) <= 0.5 && std::abs(p.z) <= 0.3; },
       {{-1, -0.7, -0.5}, {1, 0.7, 0.5}}},
      {"(rounded-box 1.6 1 0.8 0.3)",
       [](Vec3d p) {  // within 0.3 of the inner box (its nearest point: the clamp)
         const Vec3d c{std::clamp(p.x, -0.5, 0.5), std::clamp(p.y, -0.2, 0.2),
                       std::clamp(p.z, -0.1, 0.1)};
         return (p - c).length() <= 0.3;
       },
       {{-1, -0.7, -0.6}, {1, 0.7, 0.6}}},
      {"(cylinder 0.6 1.4)",
       [](Vec3d p) { return len2(p.x, p.y) <= 0.6 && std::abs(p.z) <= 0.7; },
       {{-0.8, -0.8, -0.9}, {0.8, 0.8, 0.9}}},
      {"(capsule 0.4 1)",
       [](Vec3d p) {
         return Vec3d{p.x, p.y, p.z - std::clamp(p.z, -0.5, 0.5)}.length() <= 0.4;
       },
       {{-0.6, -0.6, -1.1}, {0.6, 0.6, 1.1}}},
      {"(torus 0.7 0.25)",
       [](Vec3d p) { return std::hypot(len2(p.x, p.y) - 0.7, p.z) <= 0.25; },
       {{-1.1, -1.1, -0.45}, {1.1, 1.1, 0.45}}},
      {"(cone 0.7 1.2)",
       [](Vec3d p) { return std::abs(p.z) <= 0.6 && len2(p.x, p.y) <= 0.7 * (0.6 - p.z) / 1.2; },
       {{-0.9, -0.9, -0.8}, {0.9, 0.9, 0.8}}},
  };
}

TEST(CsgShapes, ExactShapesEqualBruteForceDistance) {
  std::mt19937 rng(7);
  const double h = 0.01;
  for (const ShapeCase& c : shape_cases()) {
    const Model m = parse(c.text);
    EXPECT_EQ(label_of(m, m.root), Label::kExact) << c.text;
    const BruteDistance brute(c.inside, c.box, h);
    std::uniform_real_distribution<double> u(0, 1);
    for (int i = 0; i < 60; ++i) {
      // Points inside the sampled box, away from its faces by more than their distance could
      // reach outside it.
      const Vec3d p{c.box.lo.x + (0.15 + 0.7 * u(rng)) * (c.box.hi.x - c.box.lo.x),
                    c.box.lo.y + (0.15 + 0.7 * u(rng)) * (c.box.hi.y - c.box.lo.y),
                    c.box.lo.z + (0.15 + 0.7 * u(rng)) * (c.box.hi.z - c.box.lo.z)};
      const double want = brute.signed_distance(p);
      if (std::abs(want) > 0.15 * std::min({c.box.hi.x - c.box.lo.x, c.box.hi.y - c.box.lo.y,
                                            c.box.hi.z - c.box.lo.z}))
        continue;  // the nearest boundary might lie outside the sampled box
      EXPECT_NEAR(evaluate(m, p), want, 1.5 * h)
          << c.text << " at " << p.x << "," << p.y << "," << p.z;
    }
  }
}

TEST(CsgShapes, EllipsoidIsRightInSignAndZeroOnTheSurface) {
  const Model m = parse("(ellipsoid 1 0.5 0.3)");
  EXPECT_EQ(label_of(m, m.root), Label::kApproximate);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  for (int i = 0; i < 2000; ++i) {
    const Vec3d p{u(rng), u(rng) * 0.6, u(rng) * 0.4};
    const double k = p.x * p.x + p.y * p.y / 0.25 + p.z * p.z / 0.09;
    if (std::abs(k - 1) < 1e-9) continue;
    EXPECT_EQ(evaluate(m, p) <= 0, k <= 1);
    const Vec3d s = Vec3d{p.x, p.y / 0.5, p.z / 0.3}.normalized();  // onto the surface
    EXPECT_NEAR(evaluate(m, {s.x, s.y * 0.5, s.z * 0.3}), 0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(evaluate(m, {0, 0, 0}), -0.3);
}

TEST(CsgLanguage, HandWorkedModels) {
  // Union of a sphere and a moved box; a difference; transforms; modifiers.
  EXPECT_DOUBLE_EQ(evaluate(parse("(union (sphere 1) (move 3 0 0 (cube 2)))"), {1.5, 0, 0}), 0.5);
  EXPECT_DOUBLE_EQ(evaluate(parse("(diff (sphere 2) (sphere 1))"), {0, 0, 0}), 1.0);
  EXPECT_DOUBLE_EQ(evaluate(parse("(inter (sphere 2) (move 1 0 0 (sphere 2)))"), {-1.5, 0, 0}),
                   0.5);
  EXPECT_NEAR(evaluate(parse("(rotate-z 90 (move 2 0 0 (sphere 1)))"), {0, 2, 0}), -1, 1e-12);
  EXPECT_NEAR(evaluate(parse("(rotate 90 0 0 5 (move 2 0 0 (sphere 1)))"), {0, 2, 0}), -1, 1e-12);
  EXPECT_DOUBLE_EQ(evaluate(parse("(scale 2 (sphere 1))"), {3, 0, 0}), 1.0);
  EXPECT_DOUBLE_EQ(evaluate(parse("(round 0.5 (cube 2))"), {2, 0, 0}), 0.5);
  EXPECT_DOUBLE_EQ(evaluate(parse("(shell 0.2 (sphere 1))"), {0, 0, 0}), 0.9);
  EXPECT_DOUBLE_EQ(evaluate(parse("(plane 0 0 2 1)"), {5, 5, 3}), 2.0);  // the normal is normalised
  // Smooth union of two spheres touching at x = 1: h = 1, so min - k/4.
  EXPECT_DOUBLE_EQ(
      evaluate(parse("(smooth-union 0.4 (sphere 1) (move 2 0 0 (sphere 1)))"), {1, 0, 0}), -0.1);
  EXPECT_DOUBLE_EQ(
      evaluate(parse("(smooth-diff 0.4 (sphere 1) (move 2 0 0 (sphere 1)))"), {1, 0, 0}), 0.1);
  // Definitions, numbers in any notation, comments, JSON.
  const Model d =
      parse("; two uses of one name\n(define s (sphere 1e0))\n(union s (move +2.5 0 0 s))");
  EXPECT_EQ(d.nodes.size(), 3u);
  EXPECT_EQ(model_info(d).nodes, 4);
  EXPECT_DOUBLE_EQ(evaluate(d, {2.5, 0, 0}), -1.0);
  const Model j =
      parse(R"([["define", "s", ["sphere", 1]], ["union", "s", ["move", 2.5, 0, 0, "s"]]])");
  EXPECT_DOUBLE_EQ(evaluate(j, {2.5, 0, 0}), -1.0);
  EXPECT_DOUBLE_EQ(evaluate(parse(R"(["cube", 2])"), {3, 0, 0}), 2.0);
}

TEST(CsgLanguage, MaterialsFollowTheWinningBranch) {
  const Model m = parse(R"((union (paint 5 (sphere 1)) (paint "#ff0000" (move 3 0 0 (sphere 1)))
                             (diff (paint 7 (move 6 0 0 (sphere 1))) (paint 9 (move 6.5 0 0 (sphere 0.2))))))");
  EXPECT_EQ(material_at(m, {0, 0, 0}), 5);
  const std::uint8_t red = material_at(m, {3, 0, 0});
  EXPECT_EQ(red, 255);
  EXPECT_EQ(m.palette[red], (Rgba{255, 0, 0, 255}));
  EXPECT_EQ(material_at(m, {5.5, 0, 0}), 7);  // a difference keeps its first operand's paint
  EXPECT_EQ(material_at(parse("(paint 3 (paint 4 (sphere 1)))"), {0, 0, 0}), 4);  // innermost wins
  EXPECT_EQ(material_at(parse("(sphere 1)"), {0, 0, 0}), kDefaultMaterial);
}

TEST(CsgLanguage, ErrorsNameLineAndColumn) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"(sphere -1)", "test.sdf:1:9: (sphere r): r must be > 0, got -1"},
      {"(union\n  (sphre 1))", "test.sdf:2:4: unknown shape or operation \"sphre\""},
      {"(box 1 2)", "test.sdf:1:1: (box x y z) got 2 arguments"},
      {"(union (sphere 1)", "test.sdf:1:1: '(' is never closed"},
      {"(union (sphere 1)))", "test.sdf:1:19: unexpected ')'"},
      {"(move 1 0 0 ball)", "test.sdf:1:13: \"ball\" is not defined"},
      {"(define a (sphere 1))\n(define a (cube 1))\na", "test.sdf:2:9: \"a\" is already defined"},
      {"(sphere 1) (cube 1)", "test.sdf:1:12: a model has one expression"},
      {"(paint 1.5 (sphere 1))", "test.sdf:1:8: (paint M EXPR): M must be a palette index"},
      {"(sphere 1e400)", "test.sdf:1:9: number 1e400 is out of range"},
      {"(sphere 12x)", "test.sdf:1:9: \"12x\" is not a number"},
      {"(rounded-box 1 1 1 0.6)", "test.sdf:1:20: (rounded-box x y z r): r must be at most half"},
      {"(rotate 30 0 0 0 (sphere 1))", "test.sdf:1:12: (rotate): the axis must not be zero"},
      {"(define union (sphere 1)) union", "test.sdf:1:9: \"union\" is a keyword"},
      {"[\"sphere\",\n  -1]", "test.sdf:2:3: (sphere r): r must be > 0, got -1"},
      {"[\"sphere\", 1", "test.sdf:1:13: invalid JSON"},
      {"[\"sphere\", {\"r\": 1}]", "test.sdf:1:12: a object has no meaning"},
      {"", "test.sdf:1:1: no model expression"},
  };
  for (const auto& c : cases) {  // (not a structured binding: clang 14 cannot capture one)
    const std::string& text = c.first;
    const std::string& want = c.second;
    const std::string got = error_of([&] { (void)parse(text); });
    EXPECT_EQ(got.substr(0, want.size()), want) << "text: " << text << "\ngot: " << got;
  }
  std::string deep;
  for (int i = 0; i < 300; ++i) deep += "(round 0 ";
  EXPECT_NE(error_of([&] { (void)parse(deep); }).find("nested deeper than 256"), std::string::npos);
  // A definition used twice in each of 25 levels expands to 2^25 nodes: refused, not expanded.
  std::string bomb = "(define d0 (sphere 1))\n";
  for (int i = 1; i <= 25; ++i)
    bomb += "(define d" + std::to_string(i) + " (union d" + std::to_string(i - 1) + " d" +
            std::to_string(i - 1) + "))\n";
  bomb += "d25";
  EXPECT_NE(error_of([&] { (void)parse(bomb); }).find("more than 2^20 nodes"), std::string::npos);
}

// ---- random models -----------------------------------------------------------------------------

std::string random_expr(std::mt19937& rng, int depth) {
  std::uniform_real_distribution<double> u(0, 1);
  auto num = [&](double lo, double hi) {
    std::ostringstream s;
    s.precision(17);
    s << lo + (hi - lo) * u(rng);
    return s.str();
  };
  const int pick = depth <= 0 ? static_cast<int>(u(rng) * 8) : static_cast<int>(u(rng) * 20);
  switch (pick) {
    case 0:
      return "(sphere " + num(0.3, 1.5) + ")";
    case 1:
      return "(box " + num(0.4, 2) + " " + num(0.4, 2) + " " + num(0.4, 2) + ")";
    case 2:
      return "(rounded-box 2 1.5 1 " + num(0, 0.5) + ")";
    case 3:
      return "(cylinder " + num(0.3, 1) + " " + num(0.5, 2) + ")";
    case 4:
      return "(capsule " + num(0.2, 0.6) + " " + num(0, 1.5) + ")";
    case 5:
      return "(torus " + num(0.8, 1.2) + " " + num(0.1, 0.4) + ")";
    case 6:
      return "(cone " + num(0.4, 1) + " " + num(0.5, 1.5) + ")";
    case 7:
      return "(ellipsoid " + num(0.4, 1.2) + " " + num(0.4, 1.2) + " " + num(0.4, 1.2) + ")";
    case 8:
      return "(move " + num(-1, 1) + " " + num(-1, 1) + " " + num(-1, 1) + " " +
             random_expr(rng, depth - 1) + ")";
    case 9:
      return "(rotate " + num(-180, 180) + " " + num(-1, 1) + " " + num(-1, 1) + " 0.5 " +
             random_expr(rng, depth - 1) + ")";
    case 10:
      return "(scale " + num(0.5, 2) + " " + random_expr(rng, depth - 1) + ")";
    case 11:
      return "(round " + num(0, 0.3) + " " + random_expr(rng, depth - 1) + ")";
    case 12:
      return "(shell " + num(0.05, 0.3) + " " + random_expr(rng, depth - 1) + ")";
    case 13:
      return "(paint " + std::to_string(2 + static_cast<int>(u(rng) * 10)) + " " +
             random_expr(rng, depth - 1) + ")";
    default: {
      static const char* ops[] = {"union",        "inter",        "diff",
                                  "smooth-union", "smooth-inter", "smooth-diff"};
      const int op = static_cast<int>(u(rng) * 6);
      std::string s = std::string("(") + ops[op] + (op >= 3 ? " " + num(0.1, 0.8) : "");
      const int n = 2 + static_cast<int>(u(rng) * 3);
      for (int i = 0; i < n; ++i) s += " " + random_expr(rng, depth - 1);
      return s + ")";
    }
  }
}

Model random_model(std::uint32_t seed) {
  std::mt19937 rng(seed);
  return parse("(union " + random_expr(rng, 4) + " " + random_expr(rng, 4) + ")");
}

Vec3d random_point(std::mt19937& rng, const Bounds& b) {
  std::uniform_real_distribution<double> u(0, 1);
  return {b.lo.x + u(rng) * (b.hi.x - b.lo.x), b.lo.y + u(rng) * (b.hi.y - b.lo.y),
          b.lo.z + u(rng) * (b.hi.z - b.lo.z)};
}

TEST(CsgTape, EqualsTheReferenceOnRandomModels) {
  std::mt19937 rng(11);
  for (std::uint32_t seed = 0; seed < 200; ++seed) {
    const Model m = random_model(seed);
    const Tape t = compile_tape(m);
    std::vector<Vec3d> points;
    for (int i = 0; i < 100; ++i) points.push_back(random_point(rng, {{-3, -3, -3}, {3, 3, 3}}));
    std::vector<double> values(points.size());
    std::vector<std::uint8_t> mats(points.size());
    evaluate(t, points, values, mats);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const double want = evaluate(m, points[i]);
      ASSERT_NEAR(values[i], want, 1e-9 * (1 + std::abs(want))) << "seed " << seed;
      // Materials may differ only where two branches tie within rounding.
      if (std::abs(want) > 1e-6 && material_at(m, points[i]) != mats[i]) {
        ADD_FAILURE() << "seed " << seed << " material " << int(mats[i]) << " vs "
                      << int(material_at(m, points[i]));
      }
    }
  }
}

TEST(CsgBounds, ContainEveryInsidePoint) {
  std::mt19937 rng(5);
  for (std::uint32_t seed = 0; seed < 200; ++seed) {
    const Model m = random_model(seed);
    const auto b = model_bounds(m);
    ASSERT_TRUE(b) << seed;
    for (int i = 0; i < 400; ++i) {
      const Vec3d p = random_point(rng, {{-5, -5, -5}, {5, 5, 5}});
      if (evaluate(m, p) > 0) continue;
      for (int a = 0; a < 3; ++a)
        ASSERT_TRUE(p[a] >= b->lo[a] - 1e-9 && p[a] <= b->hi[a] + 1e-9)
            << "seed " << seed << " axis " << a;
    }
  }
}

// Pruning soundness: in random cells of random models, the clipped tape equals the whole tape bit
// for bit (value and material) at random points of the cell; cells called empty or full have no
// sign change on a dense lattice.
TEST(CsgClip, PrunedTapesEqualTheWholeTapeAndSettledCellsHaveNoSurface) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(0, 1);
  std::int64_t pruned_cells = 0, settled = 0;
  for (std::uint32_t seed = 0; seed < 300; ++seed) {
    const Model m = random_model(seed);
    const Tape whole = compile_tape(m);
    for (int cell = 0; cell < 12; ++cell) {
      const double edge = 0.05 + u(rng) * 1.5;
      const Vec3d lo = random_point(rng, {{-3, -3, -3}, {3 - edge, 3 - edge, 3 - edge}});
      const Bounds box{lo, lo + Vec3d{edge, edge, edge}};
      const Clipped c = clip(whole, box);
      pruned_cells += c.tape.code.size() < whole.code.size();
      std::vector<Vec3d> points;
      for (int i = 0; i < 64; ++i) points.push_back(random_point(rng, box));
      for (int i = 0; i < 8; ++i)
        points.push_back({i & 1 ? box.hi.x : box.lo.x, i & 2 ? box.hi.y : box.lo.y,
                          i & 4 ? box.hi.z : box.lo.z});
      std::vector<double> a(points.size()), b(points.size());
      std::vector<std::uint8_t> ma(points.size()), mb(points.size());
      evaluate(whole, points, a, ma);
      evaluate(c.tape, points, b, mb);
      for (std::size_t i = 0; i < points.size(); ++i) {
        ASSERT_EQ(a[i], b[i]) << "seed " << seed << " cell " << cell;
        ASSERT_EQ(ma[i], mb[i]) << "seed " << seed << " cell " << cell;
        ASSERT_LE(c.lo, a[i]);
        ASSERT_GE(c.hi, a[i]);
      }
      if (c.state == CellState::kSurface) continue;
      ++settled;
      for (int z = 0; z <= 6; ++z)
        for (int y = 0; y <= 6; ++y)
          for (int x = 0; x <= 6; ++x) {
            const double v =
                evaluate(whole, box.lo + Vec3d{x * edge / 6, y * edge / 6, z * edge / 6});
            ASSERT_TRUE(c.state == CellState::kEmpty ? v > 0 : v < 0) << "seed " << seed;
          }
      if (c.material >= 0 && c.state == CellState::kFull) {
        for (std::uint8_t mat : ma) ASSERT_EQ(mat, c.material);
      }
    }
  }
  EXPECT_GT(pruned_cells, 1000);  // the test exercises pruning, not only whole tapes
  EXPECT_GT(settled, 500);
}

// Large coordinates and radii, small cells: the bounds must cover the rounding of values computed
// from numbers a million times larger than the cell (the margin scales with them).
TEST(CsgClip, SoundAtLargeCoordinates) {
  const Model m = parse(
      "(union (move 1e6 0 0 (sphere 1e6)) (move -1e6 0.5 0 (sphere 1e6)) (move 0 3e6 0 (box 2e6 "
      "2e6 2e6)))");
  const Tape whole = compile_tape(m);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  for (int cell = 0; cell < 3000; ++cell) {
    // Cells of 1e-3 near the spheres' touching point and the box's face.
    const Vec3d lo =
        cell % 2 ? Vec3d{(u(rng) - 0.5) * 0.1, (u(rng) - 0.5) * 2, (u(rng) - 0.5) * 2}
                 : Vec3d{(u(rng) - 0.5) * 1e3, 2e6 + (u(rng) - 0.5) * 0.01, (u(rng) - 0.5) * 1e3};
    const Bounds box{lo, lo + Vec3d{1e-3, 1e-3, 1e-3}};
    const Clipped c = clip(whole, box);
    for (int i = 0; i < 8; ++i) {
      const Vec3d p{i & 1 ? box.hi.x : box.lo.x, i & 2 ? box.hi.y : box.lo.y,
                    i & 4 ? box.hi.z : box.lo.z};
      const double v = evaluate(whole, p);
      ASSERT_EQ(evaluate(c.tape, p), v);
      ASSERT_TRUE(c.lo <= v && v <= c.hi) << cell;
      if (c.state == CellState::kEmpty) {
        ASSERT_GT(v, 0);
      }
      if (c.state == CellState::kFull) {
        ASSERT_LT(v, 0);
      }
    }
  }
}

TEST(CsgTape, ScalesThatUnderflowAreRefused) {
  std::string deep = "(sphere 1)";
  for (int i = 0; i < 12; ++i) deep = "(scale 1e-12 " + deep + ")";
  EXPECT_NE(error_of([&] { (void)compile_tape(parse(deep)); }).find("out of range"),
            std::string::npos);
  EXPECT_NE(error_of([] { (void)parse("(sphere 1e-13)"); }).find("at least 1e-12"),
            std::string::npos);
}

TEST(CsgOctree, GearHasFewVariantsAndPrunedValuesAgree) {
  const Model gear = parse_model(test::csg_example_text("gear.sdf"), "gear.sdf");
  const Tape whole = compile_tape(gear);
  OctreeOptions o;
  o.depth = 5;
  const Octree tree = build_octree(whole, gear, o);
  EXPECT_LE(tree.stats.variants, 10);
  EXPECT_GT(tree.stats.surface, 100);
  EXPECT_LT(tree.stats.mean_nodes * 4, static_cast<double>(tree.stats.whole_nodes));
  std::mt19937 rng(2);
  for (int i = 0; i < 20000; ++i) {
    const Vec3d p = random_point(rng, tree.root);
    const double want = evaluate(whole, p), got = tree.evaluate(p);
    const OctreeLeaf& l = tree.leaves[static_cast<std::size_t>(*tree.leaf_at(p))];
    if (l.state == CellState::kSurface) {
      ASSERT_EQ(got, want);
    } else {
      ASSERT_EQ(got > 0, want > 0);
      ASSERT_LE(std::abs(got), std::abs(want));
    }
  }
}

TEST(CsgVoxelize, EqualsPointEvaluationAndTheWholeTape) {
  for (const char* name : {"gear.sdf", "blobs.sdf", "building.sdf"}) {
    const Model m = parse_model(test::csg_example_text(name), name);
    VoxelizeOptions o;
    o.voxel_size = 0.37;
    o.field = true;
    const Voxelized pruned = voxelize(m, o);
    o.prune = false;
    const Voxelized whole = voxelize(m, o);
    ASSERT_EQ(pruned.field, whole.field) << name;
    EXPECT_LT(pruned.stats.mean_nodes * 2, whole.stats.mean_nodes) << name;
    EXPECT_EQ(pruned.stats.evaluated, pruned.stats.voxels) << name;  // exact values everywhere
    o.prune = true;
    o.field = false;  // occupancy only: empty and full cells need no evaluation
    const Voxelized occupancy = voxelize(m, o);
    EXPECT_LT(occupancy.stats.evaluated, occupancy.stats.voxels) << name;
    std::int64_t solid = 0;
    for (int z = 0; z < pruned.dims.z; ++z)
      for (int y = 0; y < pruned.dims.y; ++y)
        for (int x = 0; x < pruned.dims.x; ++x) {
          const Vec3d c = pruned.box.lo + Vec3d{x + 0.5, y + 0.5, z + 0.5} * o.voxel_size;
          const double v = evaluate(m, c);
          const std::uint8_t mat = pruned.world.voxels.get({x, y, z});
          ASSERT_EQ(mat != 0, v <= 0) << name;
          if (mat) {
            ASSERT_EQ(mat, material_at(m, c)) << name;
          }
          ASSERT_EQ(whole.world.voxels.get({x, y, z}), mat);
          ASSERT_EQ(occupancy.world.voxels.get({x, y, z}), mat);
          solid += mat != 0;
        }
    EXPECT_GT(solid, 100) << name;
  }
  // A clamped field settles far cells without evaluating them.
  const Model gear = parse_model(test::csg_example_text("gear.sdf"), "gear.sdf");
  VoxelizeOptions o;
  o.voxel_size = 0.1;
  o.field = true;
  o.max_distance = 0.2;
  const Voxelized clamped = voxelize(gear, o);
  EXPECT_LT(clamped.stats.evaluated * 3, clamped.stats.voxels * 2);
  for (float f : clamped.field) ASSERT_LE(std::abs(f), 0.2f);
}

TEST(CsgVoxelize, RefusesUnboundedModelsAndAbsurdSizes) {
  EXPECT_NE(error_of([] { (void)voxelize(parse("(plane 0 0 1 0)"), {}); }).find("unbounded"),
            std::string::npos);
  VoxelizeOptions o;
  o.voxel_size = 1e-6;
  EXPECT_NE(error_of([&] { (void)voxelize(parse("(sphere 10)"), o); }).find("voxelising"),
            std::string::npos);
}

TEST(CsgGlsl, InterpreterProgramsEncodeTheTape) {
  const Tape t = compile_tape(parse("(smooth-union 0.5 (sphere 1) (move 2 0 0 (box 1 2 3)))"));
  const std::vector<std::uint32_t> program = interpreter_program(t);
  ASSERT_EQ(program.size(), 1 + 4 * t.code.size());
  EXPECT_EQ(program[0], t.code.size());
  std::uint32_t constants = 0;
  for (std::size_t i = 0; i < t.code.size(); ++i) {
    const std::uint32_t* w = &program[1 + 4 * i];
    EXPECT_EQ(w[0] & 0xFFu, static_cast<std::uint32_t>(t.code[i].op));
    EXPECT_EQ(w[1], t.reg[i]);
    if (t.code[i].op == OpCode::kShape) {
      EXPECT_EQ((w[0] >> 8) & 0xFFu, static_cast<std::uint32_t>(t.code[i].shape));
    }
    EXPECT_EQ(w[0] >> 24, t.code[i].material);
    constants += (w[0] >> 16) & 0xFFu;
  }
  EXPECT_EQ(constants, t.params.size()) << "the program reads every constant once, in order";
  EXPECT_EQ(program[1 + 4 * (t.code.size() - 1) + 2], t.reg[t.code.back().a]);
}

TEST(CsgGlsl, EveryVariantOfTheExamplesCompiles) {
#ifndef VOXFIELD_GLSLC
  GTEST_SKIP() << "glslc not found at configure time";
#else
  const auto dir =
      std::filesystem::temp_directory_path() / ("voxfield_csg_glsl_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* name : {"gear.sdf", "blobs.sdf", "building.sdf", "menger.sdf"}) {
    const Model m = parse_model(test::csg_example_text(name), name);
    const Tape whole = compile_tape(m);
    OctreeOptions o;
    o.depth = 3;
    const Octree tree = build_octree(whole, m, o);
    std::ostringstream src;
    src << "#version 450\nlayout(local_size_x = 64) in;\n"
        << "layout(std430, binding = 0) readonly buffer P { float vf_params[]; };\n"
        << "layout(std430, binding = 1) writeonly buffer O { float vf_out[]; };\n"
        << "float vf_param(uint i) { return vf_params[i]; }\n"
        << glsl_prelude();
    for (std::size_t v = 0; v < tree.variants.size(); ++v)
      src << glsl_variant(tree.variants[v].tape, static_cast<int>(v));
    src << glsl_variant(whole, 999);
    src << "void main() {\n  vec3 p = vec3(gl_GlobalInvocationID);\n  uint m, mats = 0u;\n"
        << "  float s = vf_variant_999(p, 0u, m);\n";
    for (std::size_t v = 0; v < tree.variants.size(); ++v)
      src << "  s += vf_variant_" << v << "(p, 0u, m);\n  mats += m;\n";
    src << "  vf_out[gl_GlobalInvocationID.x] = s + float(mats);\n}\n";
    const auto file = dir / (std::string(name) + ".comp");
    std::ofstream(file) << src.str();
    const std::string cmd = std::string(VOXFIELD_GLSLC) + " --target-env=vulkan1.1 -o " +
                            (dir / "out.spv").string() + " " + file.string();
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
  std::filesystem::remove_all(dir);
#endif
}

}  // namespace
}  // namespace voxfield::csg
