// Vector textures in three storages (docs/vectors.md, "Storage"): the paper's RGBA8 with its
// rounding defined, IEEE half floats (rounded to nearest even) and floats.
#include <bit>
#include <cmath>
#include <cstring>

#include "texel_codec.h"
#include "voxfield/error.h"
#include "voxfield/limits.h"
#include "voxfield/vectors.h"

namespace voxfield {
using detail::vectors::Codec;
using detail::vectors::with_codec;

VectorTexture::VectorTexture(Vec3i resolution, VectorStorage storage)
    : resolution_(resolution), storage_(storage) {
  for (int a = 0; a < 3; ++a)
    if (resolution[a] < 1 || resolution[a] > 4096)
      throw InvalidArgument("vector texture: the resolution must be 1..4096 on every axis (got " +
                            to_string(resolution) + ")");
  const std::uint64_t need =
      dense_bytes(Box3i::from_size(resolution), static_cast<std::uint64_t>(bytes_per_texel()));
  require_memory(need, 0, "vector texture " + to_string(resolution),
                 std::string("its ") + vector_storage_name(storage) + " texels");
  bytes_.assign(static_cast<std::size_t>(need), 0);
  clear();
}

int VectorTexture::bytes_per_texel() const {
  return storage_ == VectorStorage::kRgba8 ? 4 : storage_ == VectorStorage::kRgba16f ? 8 : 16;
}

void VectorTexture::clear() {
  with_codec(storage_, [&](auto codec) {
    using C = decltype(codec);
    for (std::size_t i = 0; i < bytes_.size(); i += C::kBytes) C::store_zero(bytes_.data() + i);
  });
}

VectorTexel VectorTexture::get(std::int64_t index) const {
  const std::uint8_t* p = bytes_.data() + index * bytes_per_texel();
  return with_codec(storage_, [&](auto codec) { return decltype(codec)::load(p); });
}

void VectorTexture::set(std::int64_t index, const VectorTexel& t) {
  std::uint8_t* p = bytes_.data() + index * bytes_per_texel();
  with_codec(storage_, [&](auto codec) { decltype(codec)::store(p, t); });
}

VectorTexel VectorTexture::quantize(const VectorTexel& texel, VectorStorage storage) {
  VectorTexture one(Vec3i{1, 1, 1}, storage);
  one.set(0, texel);
  return one.get(0);
}

}  // namespace voxfield
