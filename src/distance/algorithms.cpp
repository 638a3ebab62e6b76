// voxfield — runs the dissertation's algorithm family and measures it against the exact field.
#include "voxfield/algorithms.h"
#include "voxfield/dissertation_format.h"

#include <chrono>

#include "family/dense_problem.h"
#include "family_driver.h"
#include "field_plan.h"
#include "voxfield/parallel.h"

namespace voxfield {
namespace {

using detail::DenseProblem;
using detail::DenseSolution;

constexpr std::pair<Algorithm, const char*> kNames[] = {
    {Algorithm::kExact, "exact"},
    {Algorithm::kBrute, "brute"},
    {Algorithm::kBruteChunked, "brute-chunked"},
    {Algorithm::kFim, "fim"},
    {Algorithm::kJfaSeed, "jfa-seed"},
    {Algorithm::kJfa, "jfa"},
    {Algorithm::kJfa1, "jfa+1"},
    {Algorithm::kJfa2, "jfa+2"},
    {Algorithm::kHybrid, "hybrid"},
    {Algorithm::kLod, "lod"},
};

DenseProblem make_problem(const World& world, const detail::FieldPlan& plan, bool sites_are_solid) {
  DenseProblem p;
  p.box = plan.domain;
  p.n = plan.domain.size();
  p.metric = plan.metric;
  p.spacing = plan.spacing;
  p.chunk_edge = world.voxels.chunk_edge();
  p.site.resize(static_cast<std::size_t>(plan.domain.volume()));
  world.voxels.copy_to_dense(plan.domain, p.site.data());
  for (auto& s : p.site) s = (s != 0) == sites_are_solid;
  return p;
}

DenseSolution solve(const DenseProblem& p, const AlgorithmOptions& a, AlgorithmStats& stats) {
  DenseSolution s;
  switch (a.algorithm) {
    case Algorithm::kExact:
      break;  // handled by the caller
    case Algorithm::kBrute:
      detail::brute_force(p, s, stats, a.brute_max_work);
      break;
    case Algorithm::kBruteChunked:
      detail::brute_chunked(p, s, stats);
      break;
    case Algorithm::kFim:
      detail::fast_iterative(p, s, stats, {});
      break;
    case Algorithm::kJfaSeed:
      detail::jump_flood_seed(p, s, stats);
      break;
    case Algorithm::kJfa:
      detail::jump_flood(p, s, stats, {});
      break;
    case Algorithm::kJfa1:
      detail::jump_flood(p, s, stats, {1});
      break;
    case Algorithm::kJfa2:
      detail::jump_flood(p, s, stats, {2, 1});
      break;
    case Algorithm::kHybrid:
      detail::jump_flood(p, s, stats, {});
      detail::fast_iterative(p, s, stats, {});
      break;
    case Algorithm::kLod: {
      detail::jump_flood(p, s, stats, {});
      // FIM in the chunks (of the world's grid) that meet the focus box, in domain coordinates.
      const int e = p.chunk_edge;
      auto down = [e](int v) { return (v >= 0 ? v / e : -((-v + e - 1) / e)) * e; };
      const Box3i f = *a.focus;
      const Box3i chunks{{down(f.begin.x), down(f.begin.y), down(f.begin.z)},
                         {down(f.end.x - 1) + e, down(f.end.y - 1) + e, down(f.end.z - 1) + e}};
      const Box3i region{chunks.begin - p.box.begin, chunks.end - p.box.begin};
      detail::fast_iterative(
          p, s, stats,
          region.intersect(Box3i::from_size(p.n)).empty() ? Box3i{{0, 0, 0}, {0, 0, 0}} : region);
      break;
    }
  }
  return s;
}

template <class T>
DistanceField assemble(const World& world, const DistanceOptions& o, const detail::FieldPlan& plan,
                       const DenseSolution& out, const DenseSolution* in,
                       const std::vector<std::uint8_t>& solid) {
  DistanceField f;
  f.options = o;
  f.domain = plan.domain;
  f.encoding = plan.encoding;
  const Grid<std::uint8_t>& g = world.voxels;
  Grid<T> values(g.chunk_edge(), detail::field_background<T>(plan), g.bounds());
  const std::size_t n = solid.size();
  std::vector<T> dense(n);
  const auto dense_index_to_offset = [&](std::size_t from, std::int32_t to) {
    const Vec3i n3 = plan.domain.size();
    auto c = [&](std::size_t i) {
      return Vec3i{static_cast<int>(i % n3.x), static_cast<int>((i / n3.x) % n3.y),
                   static_cast<int>(i / (static_cast<std::size_t>(n3.x) * n3.y))};
    };
    const Vec3i a = c(from), b = c(static_cast<std::size_t>(to));
    return SiteOffset{static_cast<std::int16_t>(b.x - a.x), static_cast<std::int16_t>(b.y - a.y),
                      static_cast<std::int16_t>(b.z - a.z)};
  };
  std::vector<SiteOffset> sites;
  const bool want_sites = o.nearest_sites && !out.site.empty() && (!in || !in->site.empty());
  if (want_sites) sites.resize(n);
  parallel_for(n, 4096, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const bool inside = solid[i] != 0;
      double d;
      std::int32_t site = -1;
      if (inside && !plan.is_signed) {
        d = 0;
        site = static_cast<std::int32_t>(i);
      } else if (inside) {
        d = -static_cast<double>(in->d[i]);
        if (!in->site.empty()) site = in->site[i];
      } else {
        d = out.d[i];
        if (!out.site.empty()) site = out.site[i];
      }
      dense[i] = detail::encode_distance<T>(d, plan);
      if (want_sites) {
        sites[i] = (site >= 0 && std::abs(d) <= plan.clamp) ? dense_index_to_offset(i, site)
                                                            : SiteOffset{};
      }
    }
  });
  values.copy_from_dense(plan.domain, dense.data());
  f.values = std::move(values);
  if (want_sites) {
    Grid<SiteOffset> sg(g.chunk_edge(), SiteOffset{}, g.bounds());
    sg.copy_from_dense(plan.domain, sites.data());
    f.sites = std::move(sg);
  }
  return f;
}

std::vector<double> decoded(const DistanceField& f, const Box3i& box) {
  std::vector<double> out(static_cast<std::size_t>(box.volume()));
  std::visit(
      [&](const auto& g) {
        using T = typename std::decay_t<decltype(g)>::value_type;
        std::vector<T> raw(out.size());
        g.copy_to_dense(box, raw.data());
        for (std::size_t i = 0; i < raw.size(); ++i)
          out[i] = f.encoding.decode(static_cast<double>(raw[i]));
      },
      f.values);
  return out;
}

}  // namespace

const char* algorithm_name(Algorithm a) {
  for (const auto& [alg, name] : kNames)
    if (alg == a) return name;
  return "?";
}

Algorithm parse_algorithm(const std::string& name) {
  for (const auto& [alg, n] : kNames)
    if (name == n) return alg;
  throw InvalidArgument(
      "unknown algorithm \"" + name +
      "\" (exact, brute, brute-chunked, fim, jfa-seed, jfa, jfa+1, jfa+2, hybrid, lod)");
}

std::vector<Algorithm> all_algorithms() {
  std::vector<Algorithm> out;
  for (const auto& [alg, name] : kNames) out.push_back(alg);
  return out;
}

namespace detail {

DistanceField compute_with_solver(const World& world, const DistanceOptions& o,
                                  const AlgorithmOptions& a, AlgorithmStats* stats_out,
                                  const DenseSolver& solver) {
  AlgorithmStats stats;
  const auto t0 = std::chrono::steady_clock::now();
  if (a.algorithm == Algorithm::kLod && !a.focus)
    throw InvalidArgument("the lod algorithm needs a focus box");
  const detail::FieldPlan plan = detail::make_field_plan(world.voxels, o);
  std::vector<std::uint8_t> solid(static_cast<std::size_t>(plan.domain.volume()));
  world.voxels.copy_to_dense(plan.domain, solid.data());
  // Progress in solves (one per sign) and the assembly; the CPU's solvers ask between their passes
  // whether to go on, so a cancelled field stops within one pass (the GPU's, between solves).
  Progress progress(o.interrupter, std::string(algorithm_name(a.algorithm)) + " distance field",
                    plan.is_signed ? 3 : 2);
  const auto solve = [&](bool to_solid) {
    DenseProblem problem = make_problem(world, plan, to_solid);
    problem.progress = &progress;
    DenseSolution s = solver(problem, a, stats);
    progress.throw_if_cancelled();
    progress.advance();
    return s;
  };
  const DenseSolution out = solve(true);
  DenseSolution in;
  if (plan.is_signed) in = solve(false);
  auto finish = [&](DistanceField f) {
    progress.advance();
    progress.throw_if_cancelled();  // a cancel answered at the last question is honoured too
    stats.ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (stats_out) *stats_out = stats;
    f.options.interrupter = nullptr;  // the field outlives the caller's interrupter
    f.frame = world.frame;
    return f;
  };
  switch (o.storage) {
    case Storage::kU8:
      return finish(
          assemble<std::uint8_t>(world, o, plan, out, plan.is_signed ? &in : nullptr, solid));
    case Storage::kU16:
      return finish(
          assemble<std::uint16_t>(world, o, plan, out, plan.is_signed ? &in : nullptr, solid));
    case Storage::kF32:
      return finish(assemble<float>(world, o, plan, out, plan.is_signed ? &in : nullptr, solid));
  }
  throw InvalidArgument("unknown storage");
}

}  // namespace detail

DistanceField compute_distance_field(const World& world, const DistanceOptions& o,
                                     const AlgorithmOptions& a, AlgorithmStats* stats_out) {
  if (a.algorithm == Algorithm::kExact) {
    const auto t0 = std::chrono::steady_clock::now();
    DistanceField f = compute_distance_field(world, o);
    if (stats_out) {
      *stats_out = AlgorithmStats{};
      stats_out->ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    return f;
  }
  return detail::compute_with_solver(world, o, a, stats_out, solve);
}

FieldError compare_fields(const DistanceField& approx, const DistanceField& exact,
                          const World& world) {
  const Box3i box = exact.domain;
  FieldError e;
  if (box.empty()) return e;
  const std::vector<double> a = decoded(approx, box), x = decoded(exact, box);
  std::vector<std::uint8_t> solid(a.size());
  world.voxels.copy_to_dense(box, solid.data());
  const bool integer = !std::holds_alternative<Grid<float>>(exact.values);
  const bool is_signed = exact.options.signed_distance;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ++e.voxels;
    if (!is_signed && solid[i]) continue;
    ++e.air_voxels;
    if (std::isinf(a[i]) && std::isinf(x[i]) && (a[i] > 0) == (x[i] > 0)) continue;
    const double tol = integer ? 0.5 / exact.encoding.scale : 1e-4 * std::max(1.0, std::abs(x[i]));
    const double diff = a[i] - x[i];
    if (std::abs(diff) <= tol) continue;
    ++e.wrong;
    if (diff > 0) {
      ++e.too_large;
      e.max_over = std::max(e.max_over, diff);
    } else {
      ++e.too_small;
      e.max_under = std::max(e.max_under, -diff);
    }
  }
  return e;
}

std::vector<std::uint32_t> pack_dissertation_format(const World& world, const DistanceField& field,
                                                    const Box3i& box) {
  const std::vector<double> d = decoded(field, box);
  std::vector<std::uint8_t> m(d.size());
  world.voxels.copy_to_dense(box, m.data());
  std::vector<std::uint32_t> out(d.size());
  for (std::size_t i = 0; i < d.size(); ++i) {
    const double clamped = std::clamp(std::floor(std::max(d[i], 0.0)), 0.0, 255.0);
    std::uint32_t rgb332 = 0;
    if (m[i]) {
      const Rgba c = world.palette[m[i]];
      rgb332 = static_cast<std::uint32_t>((c.r >> 5) << 5 | (c.g >> 5) << 2 | (c.b >> 6));
    }
    out[i] = static_cast<std::uint32_t>(clamped) << 8 | rgb332;
  }
  return out;
}

}  // namespace voxfield
