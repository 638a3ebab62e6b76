// Vector-field test inputs shared by the CPU and GPU suites (test_vectors.cpp,
// test_gpu_vector_passes.cpp): volumes of every shape the model must handle and random sources of
// every kind.
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "voxfield/vectors.h"

namespace voxfield::test {

inline VectorVolume cube_volume(int n) {
  VectorVolume v;
  v.centre = {0, 0, 0};
  v.size = {static_cast<double>(n), static_cast<double>(n), static_cast<double>(n)};
  v.resolution = {n, n, n};
  return v;
}

// Random sources of every kind the definition must handle: sub-voxel radii, stationary ones, fast
// movers crossing the box, sources on the faces and outside it.
inline std::vector<VectorSource> random_sources(const VectorVolume& v, int count,
                                                std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  const double voxel =
      std::min({v.size.x / v.resolution.x, v.size.y / v.resolution.y, v.size.z / v.resolution.z});
  std::vector<VectorSource> out;
  for (int i = 0; i < count; ++i) {
    VectorSource s;
    const Vec3d u{unit(rng) * 1.4 - 0.2, unit(rng) * 1.4 - 0.2, unit(rng) * 1.4 - 0.2};
    s.position = v.to_world(u);
    switch (i % 5) {
      case 0:
        s.previous = s.position;
        break;  // stationary
      case 1:
        s.previous = v.to_world({unit(rng), unit(rng), unit(rng)});
        break;  // fast mover
      case 2:
        s.position = v.to_world({1.0, u.y, u.z});
        s.previous = s.position;
        break;  // + face
      default:
        s.previous = s.position + Vec3d{unit(rng) - 0.5, unit(rng) - 0.5, 0} * (3 * voxel);
    }
    s.radius = i % 4 == 3 ? voxel * (0.1 + 0.3 * unit(rng)) : voxel * (1 + 6 * unit(rng));
    out.push_back(s);
  }
  return out;
}

struct Shape {
  const char* name;
  VectorVolume volume;
};

inline std::vector<Shape> shapes() {
  std::vector<Shape> out;
  out.push_back({"cube 24", cube_volume(24)});
  VectorVolume aniso;  // the paper's quarter-resolution axis and non-cubic voxels
  aniso.centre = {3, -2, 7};
  aniso.size = {10, 6, 14};
  aniso.resolution = {32, 8, 20};
  out.push_back({"anisotropic", aniso});
  VectorVolume rotated = aniso;
  rotated.rotation = VectorVolume::rotation_about(37, {1, 2, 0.5});
  out.push_back({"rotated", rotated});
  // A rotation orthonormal only to about 5e-7, as VectorVolume::validate() still accepts, with
  // small voxels far from the origin: the passes must not assume unit axes.
  VectorVolume loose = rotated;
  loose.centre = {4000, -2500, 1200};
  loose.rotation[0].x += 4e-7;
  loose.rotation[1].y -= 3e-7;
  loose.rotation[2].z += 2e-7;
  loose.rotation[0].y += 2e-7;
  out.push_back({"rotated, orthonormal to 1e-6, far out", loose});
  VectorVolume flat = cube_volume(16);
  flat.resolution = {16, 16, 1};
  out.push_back({"one layer", flat});
  return out;
}

}  // namespace voxfield::test
