// Test helper: a smooth random volume for the meshers — a sum of `waves` sines of random direction
// and phase at `frequency` — with, when `spikes`, isolated spikes at 3 % of the samples, so that a
// surface crosses every chunk layer and every cut between them in many places.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "voxfield/box.h"

namespace voxfield::test {

inline std::vector<float> wave_volume(Vec3i n, std::uint32_t seed, int waves, double frequency,
                                      bool spikes) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<std::array<double, 4>> k(static_cast<std::size_t>(waves));
  for (auto& w : k)
    for (double& c : w) c = u(rng);
  std::vector<float> v(static_cast<std::size_t>(n.x) * n.y * n.z);
  std::size_t i = 0;
  for (int z = 0; z < n.z; ++z)
    for (int y = 0; y < n.y; ++y)
      for (int x = 0; x < n.x; ++x, ++i) {
        double s = 0;
        for (const auto& w : k)
          s += std::sin(frequency * (w[0] * x + w[1] * y + w[2] * z) + 3 * w[3]);
        v[i] = static_cast<float>(s + (spikes && u(rng) > 0.97 ? 2 * u(rng) : 0.0));
      }
  return v;
}

}  // namespace voxfield::test
