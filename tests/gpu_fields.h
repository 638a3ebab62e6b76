// Distance fields of the GPU against the CPU's, for the Vulkan suites (test_gpu.cpp,
// test_gpu_ranges.cpp): integer storage bit for bit, f32 within gpu::kF32Tolerance, the
// background outside the domain and every voxel's nearest site.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "voxfield/distance.h"
#include "voxfield/gpu_distance.h"

namespace voxfield::test {

template <class T>
std::vector<T> dense(const DistanceField& f) {
  std::vector<T> v(static_cast<std::size_t>(f.domain.volume()));
  std::get<Grid<T>>(f.values).copy_to_dense(f.domain, v.data());
  return v;
}

inline void expect_same_field(const DistanceField& gpu_field, const DistanceField& cpu_field,
                              const std::string& what) {
  ASSERT_EQ(gpu_field.domain, cpu_field.domain) << what;
  ASSERT_EQ(gpu_field.values.index(), cpu_field.values.index()) << what;
  EXPECT_EQ(gpu_field.encoding.scale, cpu_field.encoding.scale) << what;
  EXPECT_EQ(gpu_field.encoding.bias, cpu_field.encoding.bias) << what;
  if (std::holds_alternative<Grid<std::uint8_t>>(cpu_field.values)) {
    EXPECT_EQ(dense<std::uint8_t>(gpu_field), dense<std::uint8_t>(cpu_field)) << what;
  } else if (std::holds_alternative<Grid<std::uint16_t>>(cpu_field.values)) {
    EXPECT_EQ(dense<std::uint16_t>(gpu_field), dense<std::uint16_t>(cpu_field)) << what;
  } else {
    const auto a = dense<float>(gpu_field), b = dense<float>(cpu_field);
    std::size_t off = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      const bool same =
          a[i] == b[i] || std::abs(a[i] - b[i]) <= gpu::kF32Tolerance * std::abs(b[i]);
      if (!same && off++ < 5)
        ADD_FAILURE() << what << ": voxel " << i << " gpu " << a[i] << " cpu " << b[i];
    }
    EXPECT_EQ(off, 0u) << what;
  }
  // Outside the domain both read the background.
  const Vec3i outside = cpu_field.domain.end;
  EXPECT_EQ(gpu_field.distance(outside), cpu_field.distance(outside)) << what;
  // Nearest sites: the same site for every voxel, ties included.
  ASSERT_EQ(gpu_field.sites.has_value(), cpu_field.sites.has_value()) << what;
  if (cpu_field.sites) {
    std::vector<SiteOffset> a(static_cast<std::size_t>(cpu_field.domain.volume())), b(a.size());
    gpu_field.sites->copy_to_dense(gpu_field.domain, a.data());
    cpu_field.sites->copy_to_dense(cpu_field.domain, b.data());
    std::size_t off = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
      if (!(a[i] == b[i]) && off++ < 5)
        ADD_FAILURE() << what << ": voxel " << i << " site gpu (" << a[i].dx << "," << a[i].dy
                      << "," << a[i].dz << ") cpu (" << b[i].dx << "," << b[i].dy << "," << b[i].dz
                      << ")";
    EXPECT_EQ(off, 0u) << what << ": voxels with another nearest site";
  }
}

}  // namespace voxfield::test
