// voxfield — the exact transform's encoder (internal): the costs the separable passes minimised
// (distances, or squared distances for Euclidean) become the stored values of the field's type,
// rounded as distance.h documents (encode_distance in ../field_plan.h). Shared by the
// whole-field and the local passes, so that both store bit-identical values.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "../field_plan.h"

namespace voxfield::detail::exact {

using Plan = FieldPlan;

// Integer square root: floor(sqrt(n)) exactly.
inline std::uint64_t isqrt(std::uint64_t n) {
  std::uint64_t r = static_cast<std::uint64_t>(std::sqrt(static_cast<double>(n)));
  while (r > 0 && r * r > n) --r;
  while ((r + 1) * (r + 1) <= n) ++r;
  return r;
}

// Turns the costs the passes minimised into stored values of type T, everything derived from the
// plan. The rounding rule itself lives in encode_distance; only the exact integer square
// root for unit-spacing Euclidean integer storage is added here.
template <class T>
struct Encoder {
  explicit Encoder(const Plan& plan)
      : p(plan),
        none(encode_distance<T>(std::numeric_limits<double>::infinity(), plan)),
        clamp_f(static_cast<float>(std::min(plan.clamp, 3.0e38))),
        // The stored value is a plain function of the cost for unsigned fields in f32 or with an
        // integer metric (scale 1, bias 0): those rows take encode_row().
        row_path(!plan.is_signed &&
                 (std::is_same_v<T, float> || plan.metric != Metric::kEuclidean)) {}

  const Plan& p;
  T none;  // stored value for "no site within reach"
  float clamp_f;
  bool row_path;

  // `cost` is what the passes minimised (squared for Euclidean); `inside`: a solid voxel of a
  // signed field (negated).
  T encode(double cost, bool has_site, bool inside) const {
    if (!has_site)
      return encode_distance<T>(inside ? -std::numeric_limits<double>::infinity()
                                       : std::numeric_limits<double>::infinity(),
                                p);
    const double d = p.metric == Metric::kEuclidean ? std::sqrt(cost) : cost;
    if constexpr (!std::is_same_v<T, float>) {
      if (p.metric == Metric::kEuclidean && p.unit_spacing && d < p.clamp &&
          p.encoding.scale == std::floor(p.encoding.scale)) {
        // floor(sqrt(cost) * S) computed exactly in integers (cost is an integer here).
        constexpr double kMax = static_cast<double>(std::numeric_limits<T>::max());
        const std::uint64_t n = static_cast<std::uint64_t>(cost) *
                                static_cast<std::uint64_t>(p.encoding.scale * p.encoding.scale);
        const std::uint64_t r = isqrt(n);
        const double scaled =
            inside ? -static_cast<double>(r + (r * r != n ? 1 : 0)) : static_cast<double>(r);
        return static_cast<T>(std::clamp(scaled + static_cast<double>(p.encoding.bias), 0.0, kMax));
      }
    }
    return encode_distance<T>(inside ? -d : d, p);
  }

  // Branch-light encoding of a row when row_path holds: the same values as encode().
  template <class V>
  void encode_row(const V* cost, T* out, int count, V inf, V clamp_v) const {
    const bool euclid = p.metric == Metric::kEuclidean;
    for (int i = 0; i < count; ++i) {
      const V c = cost[i];
      if (!(c < inf && c <= clamp_v)) {
        out[i] = none;
      } else if constexpr (std::is_same_v<T, float>) {
        out[i] =
            std::min(euclid ? std::sqrt(static_cast<float>(c)) : static_cast<float>(c), clamp_f);
      } else {
        out[i] =
            static_cast<T>(std::min<double>(static_cast<double>(c), std::numeric_limits<T>::max()));
      }
    }
  }
};

}  // namespace voxfield::detail::exact
