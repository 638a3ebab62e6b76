// voxfield — the vector-field paper's benchmark agents (Hamlin, "Volumetric Interaction",
// section 4): seeded sources flying through a box and bouncing off its walls. `voxfield bench
// vectors`, the showcase and voxfield-demo's vectors mode drive their fields with them; an
// application can use them to try its own volumes.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "voxfield/vectors.h"

namespace voxfield {

// The paper's agents: sources flying through a 10-unit box at 2..5 units/s, bouncing off its
// walls, radius 0.8 units (5 voxels at 64^3). Seeded: the same motion for every algorithm.
class VectorAgents {
 public:
  VectorAgents(int count, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> pos(-4.2, 4.2), dir(-1, 1), speed(2, 5);
    for (int i = 0; i < count; ++i) {
      Vec3d d{dir(rng), dir(rng), dir(rng)};
      if (d.length() < 1e-3) d = {1, 0, 0};
      agents_.push_back({{pos(rng), pos(rng), pos(rng)}, d.normalized() * speed(rng)});
    }
  }
  // Moves every agent by dt seconds; returns them as sources (their segment: this step's motion).
  std::vector<VectorSource> step(double dt) {
    std::vector<VectorSource> out;
    for (Agent& a : agents_) {
      const Vec3d before = a.p;
      a.p = a.p + a.v * dt;
      for (int k = 0; k < 3; ++k)
        if (std::abs(a.p[k]) > 4.2) {
          a.v[k] = -a.v[k];
          a.p[k] = std::clamp(a.p[k], -4.2, 4.2);
        }
      out.push_back({a.p, before, 0.8});
    }
    return out;
  }

 private:
  struct Agent {
    Vec3d p, v;
  };
  std::vector<Agent> agents_;
};

// The box the agents fly in: 10 units on a side, centred at the origin.
inline VectorVolume vector_agents_volume(Vec3i resolution) {
  VectorVolume v;
  v.size = {10, 10, 10};
  v.resolution = resolution;
  return v;
}

}  // namespace voxfield
