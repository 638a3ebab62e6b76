// Vector-field textures as files (docs/vectors.md, "Files"): NumPy float32 arrays, Unreal's .fga
// text and Unity VFX Graph's .vf binary.
#include <charconv>
#include <cstring>
#include <string>

#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/vector_files.h"

namespace voxfield {
namespace {

// direction x strength of voxel i, in the box's own frame (R^T v).
Vec3d local_vector(const VectorVolume& v, const VectorTexture& t, std::int64_t i) {
  const VectorTexel x = t.get(i);
  const Vec3d w = Vec3d{x.x, x.y, x.z} * x.strength;
  return {v.rotation[0].x * w.x + v.rotation[1].x * w.y + v.rotation[2].x * w.z,
          v.rotation[0].y * w.x + v.rotation[1].y * w.y + v.rotation[2].y * w.z,
          v.rotation[0].z * w.x + v.rotation[1].z * w.y + v.rotation[2].z * w.z};
}

void append_number(std::string& s, double v) {
  char buf[32];
  // Shortest text that reads back as the same float.
  const auto r = std::to_chars(buf, buf + sizeof buf, static_cast<float>(v));
  s.append(buf, r.ptr);
  s += ',';
}

void check_matches(const VectorVolume& v, const VectorTexture& t, const char* who) {
  if (!(t.resolution() == v.resolution))
    throw InvalidArgument(std::string(who) +
                          ": the texture's resolution differs from the volume's");
}

}  // namespace

NpyVolume vector_npy(const VectorTexture& texture) {
  NpyVolume out;
  out.dtype = DType::kFloat32;
  out.dims = texture.resolution();
  out.components = 4;
  const std::int64_t n = texture.voxel_count();
  require_memory(mul_sat(static_cast<std::uint64_t>(n), 16), 0,
                 "vector texture " + to_string(texture.resolution()), "its float32 .npy copy");
  out.bytes.resize(static_cast<std::size_t>(n) * 16);
  // Component slowest (Fortran order over a[i, j, k, c]): four whole volumes one after another.
  float* f = reinterpret_cast<float*>(out.bytes.data());
  for (std::int64_t i = 0; i < n; ++i) {
    const VectorTexel t = texture.get(i);
    f[i] = t.x;
    f[n + i] = t.y;
    f[2 * n + i] = t.z;
    f[3 * n + i] = t.strength;
  }
  return out;
}

std::string encode_fga(const VectorVolume& volume, const VectorTexture& texture) {
  check_matches(volume, texture, "encode_fga");
  const Vec3i n = volume.resolution;
  if (n.x > 128 || n.y > 128 || n.z > 128)
    throw InvalidArgument(
        "an .fga vector field holds at most 128 voxels per axis (Unreal's "
        "importer refuses more); this one is " +
        to_string(n));
  std::string s =
      std::to_string(n.x) + "," + std::to_string(n.y) + "," + std::to_string(n.z) + ",\n";
  // An axis-aligned volume's corners in world space; a rotated one's in its own frame, centred at
  // the origin (give the vector-field actor the volume's centre and rotation).
  const bool rotated = !(volume.rotation == VectorVolume{}.rotation);
  const Vec3d origin = rotated ? Vec3d{0, 0, 0} : volume.centre;
  const Vec3d lo = origin - volume.size * 0.5, hi = origin + volume.size * 0.5;
  for (const Vec3d& corner : {lo, hi}) {
    for (int a = 0; a < 3; ++a) append_number(s, corner[a]);
    s += '\n';
  }
  s.reserve(s.size() + static_cast<std::size_t>(texture.voxel_count()) * 24);
  for (std::int64_t i = 0; i < texture.voxel_count(); ++i) {
    const Vec3d v = local_vector(volume, texture, i);
    for (int a = 0; a < 3; ++a) append_number(s, v[a]);
    s += '\n';
  }
  return s;
}

std::vector<std::uint8_t> encode_vf(const VectorVolume& volume, const VectorTexture& texture) {
  check_matches(volume, texture, "encode_vf");
  const Vec3i n = volume.resolution;
  if (n.x > 65535 || n.y > 65535 || n.z > 65535)
    throw InvalidArgument("a .vf vector field holds at most 65535 voxels per axis");
  require_memory(mul_sat(static_cast<std::uint64_t>(texture.voxel_count()), 12), 0,
                 "vector texture " + to_string(n), "its .vf file");
  std::vector<std::uint8_t> out{'V', 'F', '_', 'V'};
  for (int a = 0; a < 3; ++a) {
    out.push_back(static_cast<std::uint8_t>(n[a] & 0xff));
    out.push_back(static_cast<std::uint8_t>(n[a] >> 8));
  }
  out.reserve(10 + static_cast<std::size_t>(texture.voxel_count()) * 12);
  for (std::int64_t i = 0; i < texture.voxel_count(); ++i) {
    const Vec3d v = local_vector(volume, texture, i);
    for (int a = 0; a < 3; ++a) {
      const float f = static_cast<float>(v[a]);
      std::uint8_t b[4];
      std::memcpy(b, &f, 4);  // little-endian hosts (x86-64, AArch64): the file's order
      out.insert(out.end(), b, b + 4);
    }
  }
  return out;
}

}  // namespace voxfield
