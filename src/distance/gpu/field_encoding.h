// voxfield GPU backend — how the exact transform's resident field is laid out and encoded: the
// header's encoding words, the clamp's cost, rows padded to whole words, and the field rebuilt from
// the bytes read back. Internal to the distance module's GPU half (gpu_distance.cpp and its slabs).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "../field_plan.h"
#include "shaders/layout.h"
#include "voxfield/distance.h"
#include "voxfield/world.h"

namespace voxfield::gpu::detail_encoding {

template <class T>
std::uint32_t bits(T value) {
  std::uint32_t b = 0;
  std::memcpy(&b, &value, sizeof(T));
  return b;
}

template <class T>
void set_encoding(layout::Header& h, const detail::FieldPlan& plan) {
  h.clamp_pos = bits(detail::encode_distance<T>(plan.clamp, plan));
  h.clamp_neg = bits(detail::encode_distance<T>(-plan.clamp, plan));
  h.none_pos = bits(detail::encode_distance<T>(std::numeric_limits<double>::infinity(), plan));
  h.none_neg = bits(detail::encode_distance<T>(-std::numeric_limits<double>::infinity(), plan));
}

// The smallest cost whose distance is at or beyond the clamp, with the CPU's own comparison
// (d < clamp, d = sqrt(cost) for Euclidean).
inline std::uint32_t clamp_cost(const detail::FieldPlan& plan) {
  if (!std::isfinite(plan.clamp)) return layout::VF_INF;
  auto distance = [&](double cost) {
    return plan.metric == Metric::kEuclidean ? std::sqrt(cost) : cost;
  };
  double c = std::ceil(plan.metric == Metric::kEuclidean ? plan.clamp * plan.clamp : plan.clamp);
  while (c > 0 && distance(c - 1) >= plan.clamp) c -= 1;
  while (distance(c) < plan.clamp) c += 1;
  return static_cast<std::uint32_t>(std::min<double>(c, layout::VF_INF - 1.0));
}

// Values of T per word of the resident field (u8: 4, u16: 2, f32: 1).
inline std::size_t lanes_of(Storage s) {
  return s == Storage::kU8 ? 4 : s == Storage::kU16 ? 2 : 1;
}

// Voxels per stored row: x padded to whole words.
inline int row_pitch(const detail::FieldPlan& plan, Storage s) {
  const int lanes = static_cast<int>(lanes_of(s));
  return (plan.domain.size().x + lanes - 1) / lanes * lanes;
}

// The field from the resident buffer's bytes: rows of row_pitch() values of T, packed.
template <class T>
DistanceField build_field(const World& world, const DistanceOptions& options,
                          const detail::FieldPlan& plan, const std::uint8_t* stored) {
  DistanceField out;
  out.options = options;
  out.domain = plan.domain;
  out.encoding = plan.encoding;
  Grid<T> values(world.voxels.chunk_edge(), detail::field_background<T>(plan),
                 world.voxels.bounds());
  const Vec3i n = plan.domain.size();
  const std::size_t pitch = static_cast<std::size_t>(row_pitch(plan, options.storage));
  std::vector<T> dense(static_cast<std::size_t>(plan.domain.volume()));
  for (std::size_t row = 0; row < static_cast<std::size_t>(n.y) * n.z;
       ++row)  // little-endian lanes: bytes in x order
    std::memcpy(&dense[row * n.x], stored + row * pitch * sizeof(T),
                static_cast<std::size_t>(n.x) * sizeof(T));
  values.copy_from_dense(plan.domain, dense.data());
  values.compact();
  out.values = std::move(values);
  return out;
}

}  // namespace voxfield::gpu::detail_encoding
