// The definition of the field (docs/vectors.md, "The field"), its conversion pass and the
// comparison of an approximate generation against it; the algorithms live one per file (brute.cpp,
// splat.cpp, jfa.cpp) and agree with vector_at() bit for bit where they are exact.
#include <cmath>
#include <limits>
#include <string>

#include "texel_codec.h"
#include "vector_internal.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"

namespace voxfield {

using detail::vectors::Segment;

namespace {

using detail::vectors::segments_of;
using detail::vectors::texel_of;
using detail::vectors::value_of;

double angle_deg(Vec3d a, Vec3d b) {
  const double la = a.length(), lb = b.length();
  if (la == 0 || lb == 0) return 0;  // no angle where either has no direction (strength says it)
  return std::acos(std::clamp(dot(a, b) / (la * lb), -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

}  // namespace

namespace detail::vectors {
std::vector<Segment> segments_of(std::span<const VectorSource> sources) {
  std::vector<Segment> s;
  s.reserve(sources.size());
  for (const VectorSource& src : sources) s.push_back(segment_of(src));
  return s;
}
}  // namespace detail::vectors

VectorValue vector_at(Vec3d p, std::span<const VectorSource> sources, VectorRule rule) {
  int best = -1;
  double best_score = 0;
  for (std::size_t i = 0; i < sources.size(); ++i) {
    const Segment s = detail::vectors::segment_of(sources[i]);
    Vec3d q;
    const double d = detail::vectors::distance_to(s, p, q);
    if (!(d < s.radius)) continue;
    const double sc = detail::vectors::score(rule, d, s.radius);
    if (best < 0 || sc > best_score) {
      best = static_cast<int>(i);
      best_score = sc;
    }
  }
  if (best < 0) return {};
  return value_of(detail::vectors::segment_of(sources[best]), p, best);
}

std::vector<std::int32_t> vector_winners(const VectorVolume& volume,
                                         std::span<const VectorSource> sources,
                                         const VectorOptions& options, VectorPassTimes* times) {
  volume.validate();
  validate_sources(sources);
  if (sources.size() > static_cast<std::size_t>(INT32_MAX))
    throw InvalidArgument("vector field: more than 2^31 - 1 sources");
  // Per voxel: the winner (4 bytes) and splatting's best score (8) or JFA's second buffer and
  // seed scores (4 + 8).
  const std::uint64_t per_voxel = options.algorithm == VectorAlgorithm::kBrute   ? 4
                                  : options.algorithm == VectorAlgorithm::kSplat ? 12
                                                                                 : 16;
  require_memory(mul_sat(static_cast<std::uint64_t>(volume.voxel_count()), per_voxel), 0,
                 "vector field " + to_string(volume.resolution),
                 "its per-voxel winners and scratch");
  std::vector<std::int32_t> winners(static_cast<std::size_t>(volume.voxel_count()), -1);
  const std::vector<Segment> segments = segments_of(sources);
  VectorPassTimes local;
  VectorPassTimes& t = times ? *times : local;
  const std::int64_t start = detail::vectors::now_ns();
  switch (options.algorithm) {
    case VectorAlgorithm::kBrute:
      detail::vectors::brute_winners(volume, segments, options.rule, options.interrupter, winners);
      t.search_ms += detail::vectors::ms_since(start);
      break;
    case VectorAlgorithm::kSplat: {
      std::vector<double> best(winners.size(), -std::numeric_limits<double>::infinity());
      detail::vectors::splat_winners(volume, sources, segments, options.rule, options.interrupter,
                                     winners, best);
      t.search_ms += detail::vectors::ms_since(start);
      break;
    }
    case VectorAlgorithm::kJfa:
    case VectorAlgorithm::kJfaPlus1:
    case VectorAlgorithm::kJfaPlus2: {
      const int extra = options.algorithm == VectorAlgorithm::kJfa        ? 0
                        : options.algorithm == VectorAlgorithm::kJfaPlus1 ? 1
                                                                          : 2;
      detail::vectors::jfa_winners(volume, sources, segments, options.rule, extra,
                                   options.interrupter, winners, &t);
      break;
    }
  }
  return winners;
}

void write_vector_texels(const VectorVolume& volume, std::span<const VectorSource> sources,
                         std::span<const std::int32_t> winners, VectorTexture& out) {
  if (!(out.resolution() == volume.resolution) ||
      static_cast<std::int64_t>(winners.size()) != volume.voxel_count())
    throw InvalidArgument("write_vector_texels: the texture and winners must match the volume");
  const std::vector<Segment> segments = segments_of(sources);
  const detail::vectors::CentreTables centres(volume);
  const Vec3i n = volume.resolution;
  detail::vectors::with_codec(out.storage(), [&](auto codec) {
    using C = decltype(codec);
    std::uint8_t* texels = out.data();
    detail::vectors::for_each_slab(volume, nullptr, "vector conversion", [&](int k0, int k1) {
      for (int k = k0; k < k1; ++k)
        for (int j = 0; j < n.y; ++j) {
          std::int64_t idx = volume.index(0, j, k);
          for (int i = 0; i < n.x; ++i, ++idx) {
            const std::int32_t w = winners[static_cast<std::size_t>(idx)];
            std::uint8_t* p = texels + idx * C::kBytes;
            if (w < 0 || static_cast<std::size_t>(w) >= segments.size()) {
              C::store_zero(p);
              continue;
            }
            C::store(p, texel_of(value_of(segments[w], centres.at(i, j, k), w)));
          }
        }
    });
  });
}

VectorTexture generate_vectors(const VectorVolume& volume, std::span<const VectorSource> sources,
                               VectorStorage storage, const VectorOptions& options,
                               VectorPassTimes* times) {
  VectorPassTimes local;
  VectorPassTimes& t = times ? *times : local;
  const std::vector<std::int32_t> winners = vector_winners(volume, sources, options, &t);
  VectorTexture out(volume.resolution, storage);
  const std::int64_t start = detail::vectors::now_ns();
  write_vector_texels(volume, sources, winners, out);
  t.convert_ms += detail::vectors::ms_since(start);
  return out;
}

VectorError compare_vector_winners(const VectorVolume& volume,
                                   std::span<const VectorSource> sources,
                                   std::span<const std::int32_t> exact,
                                   std::span<const std::int32_t> approximate) {
  if (static_cast<std::int64_t>(exact.size()) != volume.voxel_count() ||
      approximate.size() != exact.size())
    throw InvalidArgument("compare_vector_winners: the winners must match the volume");
  const std::vector<Segment> segments = segments_of(sources);
  const detail::vectors::CentreTables centres(volume);
  VectorError e;
  e.voxels = volume.voxel_count();
  const Vec3i n = volume.resolution;
  for (int k = 0; k < n.z; ++k)
    for (int j = 0; j < n.y; ++j)
      for (int i = 0; i < n.x; ++i) {
        const std::size_t idx = static_cast<std::size_t>(volume.index(i, j, k));
        const Vec3d p = centres.at(i, j, k);
        auto value = [&](std::int32_t w) {
          return w >= 0 && static_cast<std::size_t>(w) < segments.size()
                     ? value_of(segments[w], p, w)
                     : VectorValue{};
        };
        const VectorValue a = value(exact[idx]), b = value(approximate[idx]);
        if (a.source != b.source) ++e.source_differs;
        e.max_angle_deg = std::max(e.max_angle_deg, angle_deg(a.direction, b.direction));
        e.max_strength_error = std::max(e.max_strength_error, std::abs(a.strength - b.strength));
      }
  return e;
}

}  // namespace voxfield
