// Sampling a vector texture at a world point, as a GPU samples a 3-D texture with linear
// filtering and clamp-to-edge: trilinear between voxel centres, on the decoded channels (the
// decoding is affine, so this equals decoding the filtered raw channels), and zero outside the
// box. voxfield_vectors.glsl gives shaders the same function.
#include <cmath>

#include "voxfield/error.h"
#include "voxfield/vectors.h"

namespace voxfield {

VectorSample sample_vectors(const VectorVolume& volume, const VectorTexture& texture, Vec3d world) {
  if (!(texture.resolution() == volume.resolution))
    throw InvalidArgument("sample_vectors: the texture's resolution differs from the volume's");
  VectorSample out;
  const Vec3d u = volume.to_volume(world);
  for (int a = 0; a < 3; ++a)
    if (!(u[a] >= 0.0 && u[a] <= 1.0)) return out;
  out.inside = true;
  const Vec3i n = texture.resolution();
  int i0[3], i1[3];
  double f[3];
  for (int a = 0; a < 3; ++a) {
    // Voxel-centre coordinates, clamped to the outer centres.
    const double t = std::clamp(u[a] * n[a] - 0.5, 0.0, n[a] - 1.0);
    i0[a] = static_cast<int>(std::floor(t));
    i1[a] = std::min(i0[a] + 1, n[a] - 1);
    f[a] = t - i0[a];
  }
  double acc[4] = {0, 0, 0, 0};
  for (int c = 0; c < 8; ++c) {
    const int i = c & 1 ? i1[0] : i0[0], j = c & 2 ? i1[1] : i0[1], k = c & 4 ? i1[2] : i0[2];
    const double w =
        (c & 1 ? f[0] : 1 - f[0]) * (c & 2 ? f[1] : 1 - f[1]) * (c & 4 ? f[2] : 1 - f[2]);
    const VectorTexel t =
        texture.get(i + static_cast<std::int64_t>(n.x) * (j + static_cast<std::int64_t>(n.y) * k));
    acc[0] += w * t.x;
    acc[1] += w * t.y;
    acc[2] += w * t.z;
    acc[3] += w * t.strength;
  }
  out.direction = {acc[0], acc[1], acc[2]};
  out.strength = acc[3];
  return out;
}

}  // namespace voxfield
